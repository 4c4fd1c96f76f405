"""The EKG of the thesis' log in a real Neo4j, checked against pm4py and hand counts."""

from __future__ import annotations

import uuid

import pandas as pd
import pm4py
import pytest

from robotale.ekg import build_ekg
from robotale.ekg.aggregate import aggregate
from robotale.ekg.connection import database
from robotale.ekg.logs import delete_log, list_logs, log_summary
from robotale.errors import InputError
from robotale.eventlog import schema
from robotale.queries import cypher


@pytest.fixture(scope="module")
def thesis_ekg(neo4j_driver, thesis_log):
    """The thesis' log, built once for this module (the tests leave it as they found it)."""
    name = f"test_thesis_{uuid.uuid4().hex[:8]}"
    summary = build_ekg(
        neo4j_driver,
        thesis_log,
        name,
        entities=["robot", "msg_id"],
        aggregate=["activity", "activity,robot"],
        progress=False,
    )
    yield name, summary
    delete_log(neo4j_driver, name)


def query(driver, name: str, **params) -> list[dict]:
    records, _, _ = driver.execute_query(cypher(name), params, database_=database())
    return [record.data() for record in records]


def test_counts_match_the_log(neo4j_driver, thesis_ekg, thesis_log, thesis_csv):
    name, summary = thesis_ekg
    raw = pd.read_csv(thesis_csv, dtype=str)
    robots = raw["resource"].nunique()
    messages = raw["msg_id"].dropna()
    counts = log_summary(neo4j_driver, name)["counts"]
    assert counts["events"] == len(raw) == summary.events
    assert counts["entities:robot"] == robots == 3
    assert counts["entities:msg_id"] == messages.nunique()
    assert counts["CORR:robot"] == len(raw)
    assert counts["CORR:msg_id"] == len(messages)
    # DF: every event but the first of each entity has one predecessor.
    assert counts["DF:robot"] == len(raw) - robots
    assert counts["DF:msg_id"] == len(messages) - messages.nunique()
    assert counts["classes:activity"] == raw["activity"].nunique()
    assert counts["classes:activity+robot"] == len(raw.groupby(["activity", "resource"]))
    assert summary.df_c["activity"] == sum(
        v for k, v in counts.items() if k.startswith("DF_C:activity /")
    )


def test_df_c_of_activities_per_robot_equals_pm4py(neo4j_driver, thesis_ekg, thesis_log):
    name, _ = thesis_ekg
    edges = query(neo4j_driver, "ekg_class_graph", log=name, type="activity", entityType="robot")
    ours = {(e["source"]["activity"], e["target"]["activity"]): e["count"] for e in edges}
    dfg, _, _ = pm4py.discover_dfg(
        thesis_log,
        case_id_key=schema.ROBOT,
        activity_key=schema.ACTIVITY,
        timestamp_key=schema.TIMESTAMP,
    )
    assert ours == dict(dfg)
    assert len(ours) > 20


def test_df_c_durations_are_the_mean_and_median_of_the_df_edges(
    neo4j_driver, thesis_ekg, thesis_log
):
    name, _ = thesis_ekg
    # Independently: consecutive events per robot in pandas, time then file order.
    log = thesis_log.assign(order=range(len(thesis_log)))
    log = log.sort_values([schema.ROBOT, schema.TIMESTAMP, "order"], kind="stable")
    after = log.groupby(schema.ROBOT).shift(-1)
    pairs = pd.DataFrame(
        {
            "a": log[schema.ACTIVITY],
            "b": after[schema.ACTIVITY],
            "seconds": (after[schema.TIMESTAMP] - log[schema.TIMESTAMP]).dt.total_seconds(),
        }
    ).dropna()
    expected = pairs.groupby(["a", "b"])["seconds"].agg(["count", "mean", "median"])
    edges = query(neo4j_driver, "ekg_class_graph", log=name, type="activity", entityType="robot")
    assert len(edges) == len(expected)
    for edge in edges:
        row = expected.loc[(edge["source"]["activity"], edge["target"]["activity"])]
        assert edge["count"] == row["count"]
        assert edge["meanSeconds"] == pytest.approx(row["mean"], abs=1e-3)
        assert edge["medianSeconds"] == pytest.approx(row["median"], abs=1e-3)


def test_comm_joins_each_send_to_each_receive_of_its_message(neo4j_driver, thesis_ekg, thesis_csv):
    name, summary = thesis_ekg
    edges = query(neo4j_driver, "ekg_comm_edges", log=name)
    assert edges, "the thesis log exchanges messages"
    for edge in edges:
        assert edge["sender"].endswith("!") and edge["receiver"].endswith("?")
        assert edge["msgId"] == edge["sendMsgId"] == edge["receiveMsgId"]
    raw = pd.read_csv(thesis_csv, dtype=str)
    per_message = raw.dropna(subset=["msg_id"]).groupby("msg_id")["activity"]
    sends = per_message.apply(lambda a: a.str.endswith("!").sum())
    receives = per_message.apply(lambda a: a.str.endswith("?").sum())
    assert len(edges) == summary.comm == int((sends * receives).sum())


def test_events_keep_their_time_zone_and_properties(neo4j_driver, thesis_ekg, thesis_log):
    name, _ = thesis_ekg
    event = query(neo4j_driver, "ekg_event", log=name, id="e6")[0]["e"]
    assert event["timestamp"].iso_format() == "2023-05-16T10:27:36.079000000+01:00"
    assert event["activity"] == "weed_position!"
    assert event["msg_role"] == "send" and event["msg_id"] == "m_1"
    assert event["robot"] == "drone" and event["case"] == "1" and event["order"] == 6
    assert event["x"] == pytest.approx(1.1903214526778898)


def test_classes_per_activity_and_robot(neo4j_driver, thesis_ekg, thesis_log):
    name, _ = thesis_ekg
    edges = query(
        neo4j_driver, "ekg_class_graph", log=name, type="activity+robot", entityType="robot"
    )
    for edge in edges:  # a robot's DF edges never leave the robot
        assert edge["source"]["robot"] == edge["target"]["robot"]
        assert edge["source"]["id"] == f"{edge['source']['activity']}|{edge['source']['robot']}"
    per_robot = {}
    for robot, part in thesis_log.groupby(schema.ROBOT):
        dfg, _, _ = pm4py.discover_dfg(part, case_id_key=schema.ROBOT)
        per_robot |= {(a, b, robot): n for (a, b), n in dfg.items()}
    ours = {
        (e["source"]["activity"], e["target"]["activity"], e["source"]["robot"]): e["count"]
        for e in edges
    }
    assert ours == per_robot


def test_second_ingest_is_refused_and_replace_gives_the_same_graph(
    neo4j_driver, thesis_ekg, thesis_log, graph_counts
):
    name, _ = thesis_ekg
    before = graph_counts()
    with pytest.raises(InputError, match=rf"A log named '{name}' already exists.*--replace"):
        build_ekg(neo4j_driver, thesis_log, name, entities=["robot", "msg_id"], progress=False)
    assert graph_counts() == before
    build_ekg(
        neo4j_driver,
        thesis_log,
        name,
        entities=["robot", "msg_id"],
        aggregate=["activity", "activity,robot"],
        replace=True,
        progress=False,
    )
    assert graph_counts() == before
    assert [log["status"] for log in list_logs(neo4j_driver) if log["name"] == name] == ["complete"]


def test_reaggregating_a_stored_log(neo4j_driver, thesis_ekg, graph_counts):
    name, summary = thesis_ekg
    before = graph_counts()
    assert aggregate(neo4j_driver, name, "activity") == summary.df_c["activity"]
    assert graph_counts() == before, "the old classes were replaced, not doubled"
    with pytest.raises(InputError, match="have no property 'battery' to aggregate by"):
        aggregate(neo4j_driver, name, "activity,battery")
    with pytest.raises(InputError, match="There is no log named 'no such log'"):
        aggregate(neo4j_driver, "no such log", "activity")


@pytest.mark.parametrize("entity_type", ["robot", "msg_id"])
def test_df_c_written_at_ingest_equals_pm4py_per_entity_type(
    neo4j_driver, thesis_ekg, thesis_log, entity_type
):
    """Counts, mean and median seconds of every DF_C edge, against pm4py's DFG and
    performance DFG with the entity as the case (the thesis' log is one case)."""
    name, _ = thesis_ekg
    column = {"robot": schema.ROBOT, "msg_id": schema.MSG_ID}[entity_type]
    events = thesis_log.dropna(subset=[column])
    keys = {"case_id_key": column, "activity_key": schema.ACTIVITY}
    dfg, _, _ = pm4py.discover_dfg(events, timestamp_key=schema.TIMESTAMP, **keys)
    performance, _, _ = pm4py.discover_performance_dfg(
        events, timestamp_key=schema.TIMESTAMP, **keys
    )
    edges = query(
        neo4j_driver, "ekg_class_graph", log=name, type="activity", entityType=entity_type
    )
    ours = {(e["source"]["id"], e["target"]["id"]): e for e in edges}
    assert {pair: e["count"] for pair, e in ours.items()} == dict(dfg)
    for pair, edge in ours.items():
        assert edge["meanSeconds"] == pytest.approx(performance[pair]["mean"], abs=1e-6)
        assert edge["medianSeconds"] == pytest.approx(performance[pair]["median"], abs=1e-6)
    assert len(ours) > 10 and any(e["medianSeconds"] != e["meanSeconds"] for e in edges)
