"""A live log grown batch by batch (:class:`robotale.ekg.growing.GrowingLog`): after every
batch its graph is, node for node and edge for edge, the graph ``build_ekg`` (what
``robotale ingest`` runs) makes of the same event log in one go, also where tags arrive out
of time order (a receive heard before its send; in-progress samples placed once their
activity completes); it is listed as live while it grows and complete once finished. Over
random splits of a recorded run, every relationship (type, ends, properties) of the grown log
equals the one-go build's after each batch, though an update writes only the DF_C and BEGINS
edges that changed."""

from __future__ import annotations

import hashlib
import random

import pytest
from ekg_graph import graph
from live_logs import recorded_tags

from robotale.ekg import growing as growing_module
from robotale.ekg.build import build_ekg
from robotale.ekg.connection import database
from robotale.ekg.growing import GrowingLog
from robotale.ekg.keys import built_keys, default_entities
from robotale.ekg.logs import delete_log, list_logs, log_info, stored_events
from robotale.errors import InputError
from robotale.fame_runtime.tags import Tag
from robotale.results.live import LiveEvents, tags_events

T0 = 1_800_000_000.0

#: the tags in the order a monitor hears them, cut into the batches it appends
BATCHES = [
    [Tag(T0, "rover", "survey", "start"), Tag(T0 + 0.5, "drone", "scan", "start")],
    [
        Tag(T0 + 2.0, "rover", "position?", "complete", "m1", "receive", "3,4"),
        Tag(T0 + 1.5, "drone", "position!", "start", "m1", "send", "3,4"),
        Tag(T0 + 1.6, "drone", "position!", "complete", "m1", "send", "3,4"),
    ],
    [Tag(T0 + 3.5, "rover", "survey", "complete"), Tag(T0 + 4.0, "drone", "scan", "complete")],
    [Tag(T0 + 4.0, "rover", "dock", "start")],
]


@pytest.fixture
def whole(neo4j_driver, log_name):
    name = f"{log_name}_whole"
    yield name
    delete_log(neo4j_driver, name)


def status(driver, name: str) -> str:
    return next(log["status"] for log in list_logs(driver) if log["name"] == name)


def build_in_one_go(driver, log, name: str) -> None:
    """``log`` built as ``name`` in one go, as ``robotale ingest`` builds it."""
    entities = default_entities(log.columns)
    build_ekg(
        driver,
        log,
        name,
        entities=entities,
        aggregate=built_keys(entities),
        replace=True,
        progress=False,
    )


def test_a_live_log_grown_batch_by_batch_is_the_graph_of_one_ingest_after_each(
    neo4j_driver, log_name, whole
):
    heard: list[Tag] = []
    growing = GrowingLog(neo4j_driver, log_name)
    try:
        for batch in BATCHES:
            heard += batch
            log = tags_events("run", heard)
            new = growing.update(log)
            build_in_one_go(neo4j_driver, log, whole)
            expected = graph(neo4j_driver, whole)
            assert graph(neo4j_driver, log_name) == expected
            assert stored_events(neo4j_driver, log_name) == len(log) == growing.events
            assert new > 0 and status(neo4j_driver, log_name) == "live"
        assert growing.update(tags_events("run", heard)) == 0  # nothing new: nothing written
        # the samples placed between a start and its completion are in: 3 for each activity
        assert sum(p.get("state") == "inprogress" for p in expected["events"].values()) == 6
        assert sorted(expected["comm"].values()) == [1, 1]  # the send's start and completion
        growing.finish()
    finally:
        growing.close()
    info = log_info(neo4j_driver, log_name)
    assert info["status"] == "complete" and info["events"] == len(tags_events("run", heard))
    # a new run under that name replaces the live log; a log no monitor wrote is refused
    GrowingLog(neo4j_driver, log_name).close()
    assert stored_events(neo4j_driver, log_name) == 0
    with pytest.raises(InputError, match="is not a live run's"):
        GrowingLog(neo4j_driver, whole)
    assert graph(neo4j_driver, whole) == expected


# each relationship of a log by its type, its two ends (by their keys, not Neo4j's ids) and
# its properties
_RELATIONSHIPS = """
MATCH (a {log: $log})-[r]->(b)
RETURN type(r) AS type, labels(a)[0] + ':' + coalesce(a.type, '') + ':' + a.id AS source,
       labels(b)[0] + ':' + coalesce(b.type, '') + ':' + b.id AS target,
       properties(r) AS properties
"""


def relationships(driver, name: str) -> tuple[int, str]:
    """How many relationships the log has and a digest of them all, each as text."""
    records, _, _ = driver.execute_query(_RELATIONSHIPS, log=name, database_=database())
    rows = sorted(
        repr([r["type"], r["source"], r["target"], sorted(r["properties"].items())])
        for r in records
    )
    return len(rows), hashlib.sha256("\n".join(rows).encode()).hexdigest()


@pytest.mark.parametrize("seed", [1, 2])
def test_over_random_splits_every_relationship_is_the_one_go_builds(
    neo4j_driver, log_name, whole, monkeypatch, seed
):
    """Grown as the monitor grows it: the events made again of the new tags only
    (:class:`LiveEvents`), the update told how many first events are as they were; some
    updates took events over that way (their keys and places not made again)."""
    tags, draw = recorded_tags(70, seed), random.Random(seed)
    cuts = [*sorted(draw.sample(range(1, len(tags)), 7)), len(tags)]
    made = LiveEvents()
    incremental = []  # the DF_C edges each update found written already
    write_changed = growing_module._write_changed

    def counted(loader, tx, name, kind, before, now):
        if kind is growing_module._DF_C:
            incremental.append(len(before))
        write_changed(loader, tx, name, kind, before, now)

    monkeypatch.setattr(growing_module, "_write_changed", counted)
    growing = GrowingLog(neo4j_driver, log_name)
    try:
        for cut in cuts:
            log, _, _, same = made.add("run", tags[len(made.tags) : cut])
            growing.update(log, same=same)
            log = tags_events("run", tags[:cut])  # the one go's, made independently
            build_in_one_go(neo4j_driver, log, whole)
            grown, expected = (
                relationships(neo4j_driver, log_name),
                relationships(neo4j_driver, whole),
            )
            assert grown == expected, f"after {cut} of {len(tags)} tags"
    finally:
        growing.close()
    kinds = {row["type"] for row in neo4j_driver.execute_query(
        "MATCH ({log: $log})-[r]->() RETURN DISTINCT type(r) AS type", log=log_name,
        database_=database())[0]}  # fmt: skip
    assert {"DF", "COMM", "DF_C", "BEGINS"} <= kinds
    assert any(incremental)  # some updates kept the DF_C edges written before
    assert growing.reused > 0  # some took the first events over
    assert growing.classes_reused > 0  # and their class tables' instance edges
