"""A build with several transactions in flight (``ROBOTALE_BUILD_WORKERS``) writes the same
graph as one written one batch after the other: the same nodes with the same properties, and
every relationship with its properties between the same two nodes (named by their keys, not
by Neo4j's ids), checked as counts against the log and as a digest of every relationship."""

from __future__ import annotations

import hashlib
import uuid

import pytest

from robotale.ekg import build_ekg, load
from robotale.ekg.connection import database
from robotale.ekg.logs import delete_log
from robotale.errors import InputError
from robotale.eventlog import schema

# prime and small: the thesis' log in 37 batches, so that many are in flight at once and the
# edges between two batches are written after the events
SMALL_BATCH = 101

# each node by its key within its log, each relationship by its two ends and its properties
_RELATIONSHIPS = """
MATCH (a {log: $log})-[r]->(b)
RETURN type(r) AS type, labels(a)[0] + ':' + coalesce(a.type, '') + ':' + a.id AS source,
       labels(b)[0] + ':' + coalesce(b.type, '') + ':' + b.id AS target,
       properties(r) AS properties
"""
_NODES = """
MATCH (n {log: $log}) WHERE NOT n:Log
RETURN labels(n) AS labels, properties(n) AS properties
"""


def _build(driver, log, workers: int) -> str:
    name = f"test_concurrent_{workers}_{uuid.uuid4().hex[:8]}"
    with pytest.MonkeyPatch.context() as patch:
        patch.setattr(load, "BATCH", SMALL_BATCH)
        patch.setenv(load.WORKERS_ENV, str(workers))
        build_ekg(
            driver,
            log,
            name,
            entities=["robot", "msg_id"],
            aggregate=["activity", "activity,robot"],
            progress=False,
        )
    return name


def _rows(driver, text: str, log: str) -> list[str]:
    """Each row as text, its properties (but the log's name) sorted by key; in order."""
    records, _, _ = driver.execute_query(text, log=log, database_=database())
    rows = []
    for record in records:
        *ends, properties = record.values()
        kept = sorted((k, repr(v)) for k, v in properties.items() if k != "log")
        rows.append(repr([*ends, kept]))
    return sorted(rows)


@pytest.fixture(scope="module")
def both(neo4j_driver, thesis_log):
    names = [_build(neo4j_driver, thesis_log, 1), _build(neo4j_driver, thesis_log, 4)]
    yield names
    for name in names:
        delete_log(neo4j_driver, name)


@pytest.mark.slow
def test_many_in_flight_write_the_graph_of_one_at_a_time(neo4j_driver, both, thesis_log):
    one, many = both
    edges = {log: _rows(neo4j_driver, _RELATIONSHIPS, log) for log in both}
    nodes = {log: _rows(neo4j_driver, _NODES, log) for log in both}
    digest = {log: hashlib.sha256("\n".join(edges[log]).encode()).hexdigest() for log in both}
    assert digest[one] == digest[many]
    assert nodes[one] == nodes[many]
    # counted from the log itself: an event each, a CORR edge per robot and message it names,
    # an OBSERVED edge per key
    events = len(thesis_log)
    corr = int(thesis_log[schema.ROBOT].notna().sum() + thesis_log[schema.MSG_ID].notna().sum())
    kinds = [row.split("'")[1] for row in edges[many]]
    assert sum(row.startswith("[['Event'") for row in nodes[many]) == events
    assert kinds.count("CORR") == corr
    assert kinds.count("OBSERVED") == 2 * events
    assert {"DF", "COMM", "BEGINS", "DF_C"} <= set(kinds)


def test_the_workers_setting_is_a_count(monkeypatch):
    monkeypatch.setenv(load.WORKERS_ENV, "3")
    assert load.build_workers() == 3
    monkeypatch.setenv(load.WORKERS_ENV, "")
    assert load.build_workers() == load.WORKERS >= 2
    for wrong in ("0", "two", "-1"):
        monkeypatch.setenv(load.WORKERS_ENV, wrong)
        with pytest.raises(InputError, match=load.WORKERS_ENV):
            load.build_workers()
