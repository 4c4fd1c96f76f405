"""COMM edges lifted by aggregation steps, counted by hand: a small log of two robots passing
three messages, aggregated by activity, by activity and robot, and with a `where` that leaves
the receivers on their own; undo takes the lifted COMM edges away."""

from __future__ import annotations

import pytest

from robotale.ekg.build import build_ekg
from robotale.ekg.connection import database
from robotale.ekg.spec import parse_spec
from robotale.ekg.steps import run_spec, undo
from robotale.eventlog.readers import read_csv

# r1 tells r2 twice (m1: e1 -> e2, m2: e3 -> e4), r2 tells r1 once (m3: e5 -> e6).
MESSAGES = """case,activity,time,robot,msg_id,msg_role,event_id
c1,tell,2024-01-01T10:00:00Z,r1,m1,send,e1
c1,hear,2024-01-01T10:00:01Z,r2,m1,receive,e2
c1,tell,2024-01-01T10:01:00Z,r1,m2,send,e3
c1,hear,2024-01-01T10:01:01Z,r2,m2,receive,e4
c1,tell,2024-01-01T10:02:00Z,r2,m3,send,e5
c1,hear,2024-01-01T10:02:01Z,r1,m3,receive,e6
"""


@pytest.fixture
def talking(tmp_path, neo4j_driver, log_name) -> str:
    path = tmp_path / "messages.csv"
    path.write_text(MESSAGES)
    build_ekg(neo4j_driver, read_csv(path), log_name, entities=["robot"], progress=False)
    return log_name


def comm(driver, log: str, lifted: bool = True) -> dict[tuple[str, str], int]:
    """COMM edges by (source, target): aggregates by name, events by id; the lifted ones
    (made by a step) with their counts, or the log's own with 1 each."""
    records, _, _ = driver.execute_query(
        "MATCH (a)-[r:COMM]->(b) WHERE (a.log = $log OR b.log = $log) "
        "AND (r.step IS NOT NULL) = $lifted "
        "RETURN coalesce(a.name, a.id) AS a, coalesce(b.name, b.id) AS b, r.count AS n",
        log=log,
        lifted=lifted,
        database_=database(),
    )
    return {(r["a"], r["b"]): r["n"] if lifted else 1 for r in records}


def test_the_logs_own_comm_edges_pair_each_send_with_its_receive(neo4j_driver, talking):
    assert comm(neo4j_driver, talking, lifted=False) == {("e1", "e2"): 1, ("e3", "e4"): 1,
                                                         ("e5", "e6"): 1}  # fmt: skip


def test_comm_is_lifted_with_its_counts_and_undone(neo4j_driver, talking, graph_counts):
    before = graph_counts()
    by_activity = {"aggr_type": "EVENTS", "group_by": ["activity"]}
    run_spec(neo4j_driver, talking, parse_spec({"steps": [by_activity]}))
    # tell (e1 e3 e5) -> hear (e2 e4 e6): the three messages
    assert comm(neo4j_driver, talking) == {("tell", "hear"): 3}
    assert undo(neo4j_driver, talking) == [1]
    assert comm(neo4j_driver, talking) == {}
    assert graph_counts() == before

    by_robot = {"aggr_type": "EVENTS", "group_by": ["activity", "robot"]}
    run_spec(neo4j_driver, talking, parse_spec({"steps": [by_robot]}))
    # r1 told r2 twice (m1, m2), r2 told r1 once (m3)
    assert comm(neo4j_driver, talking) == {("tell|r1", "hear|r2"): 2, ("tell|r2", "hear|r1"): 1}
    undo(neo4j_driver, talking)
    assert graph_counts() == before


def test_a_receiver_left_on_its_own_keeps_its_comm_edge_from_the_aggregate(neo4j_driver, talking):
    senders = {"aggr_type": "EVENTS", "group_by": ["activity"], "where": "activity = 'tell'"}
    run_spec(neo4j_driver, talking, parse_spec({"steps": [senders]}))
    # only e1 e3 e5 aggregated: one edge to each receiver, standing for one message
    assert comm(neo4j_driver, talking) == {("tell", "e2"): 1, ("tell", "e4"): 1,
                                           ("tell", "e6"): 1}  # fmt: skip
