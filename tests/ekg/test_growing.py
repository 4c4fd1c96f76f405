"""A live log grown batch by batch (:class:`robotale.ekg.growing.GrowingLog`): after every
batch its graph is, node for node and edge for edge, the graph ``build_ekg`` (what
``robotale ingest`` runs) makes of the same event log in one go, also where tags arrive out
of time order (a receive heard before its send; in-progress samples placed once their
activity completes); it is listed as live while it grows and complete once finished."""

from __future__ import annotations

import pytest
from ekg_graph import graph

from robotale.ekg.build import build_ekg
from robotale.ekg.growing import GrowingLog
from robotale.ekg.keys import built_keys, default_entities
from robotale.ekg.logs import delete_log, list_logs, log_info, stored_events
from robotale.errors import InputError
from robotale.fame_runtime.tags import Tag
from robotale.results.live import tags_events

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
            entities = default_entities(log.columns)
            build_ekg(
                neo4j_driver,
                log,
                whole,
                entities=entities,
                aggregate=built_keys(entities),
                replace=True,
                progress=False,
            )
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
