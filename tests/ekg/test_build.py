"""The EKG of the thesis' log in a real Neo4j, checked against pm4py and hand counts."""

from __future__ import annotations

import uuid

import pandas as pd
import pm4py
import pytest
from instance_frames import instance_frame

from robotale.discovery.ekg import discover_ekg
from robotale.ekg import build_ekg
from robotale.ekg.aggregate import aggregate
from robotale.ekg.connection import database
from robotale.ekg.logs import delete_log, list_logs, log_summary
from robotale.errors import InputError
from robotale.eventlog import schema
from robotale.eventlog.readers import read_csv
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


def class_graph(driver, name: str, kind: str, entity_type: str) -> dict:
    edges = query(driver, "ekg_class_graph", log=name, type=kind, entityType=entity_type)
    return {
        (e["source"]["id"], e["target"]["id"]): (e["count"], e["meanSeconds"], e["medianSeconds"])
        for e in edges
    }


def test_df_c_of_activities_per_robot_equals_pm4py_on_the_activity_instances(
    neo4j_driver, thesis_ekg, thesis_log
):
    """Counts, mean and median seconds of every DF_C edge against pm4py's DFG and performance
    DFG of the activity instances, each robot's flow a case (the thesis' log is one case)."""
    name, _ = thesis_ekg
    instances = instance_frame(thesis_log)
    keys = {
        "case_id_key": schema.ROBOT,
        "activity_key": schema.ACTIVITY,
        "timestamp_key": schema.TIMESTAMP,
    }
    dfg, _, _ = pm4py.discover_dfg(instances, **keys)
    performance, _, _ = pm4py.discover_performance_dfg(instances, **keys)
    ours = class_graph(neo4j_driver, name, "activity", "robot")
    assert {pair: count for pair, (count, _, _) in ours.items()} == dict(dfg)
    for pair, (_, mean, median) in ours.items():
        assert mean == pytest.approx(performance[pair]["mean"], abs=1e-6)
        assert median == pytest.approx(performance[pair]["median"], abs=1e-6)
    # figure 7.4's edge: an Explore the low battery interrupted is an instance too
    assert len(ours) > 20 and sum(count for count, _, _ in ours.values()) == len(instances) - 3


def test_df_c_of_messages_counts_consecutive_instances(neo4j_driver, thesis_ekg, thesis_log):
    """Each message's instances in pandas, in time then log order (pm4py orders the events
    of one instant otherwise, and a message's send and receive often share one)."""
    name, _ = thesis_ekg
    instances = instance_frame(thesis_log).dropna(subset=[schema.MSG_ID])
    instances = instances.sort_values(schema.MSG_ID, kind="stable")
    after = instances.groupby(schema.MSG_ID)[[schema.ACTIVITY, schema.TIMESTAMP]].shift(-1)
    pairs = pd.DataFrame(
        {
            "a": instances[schema.ACTIVITY],
            "b": after[schema.ACTIVITY],
            "seconds": (after[schema.TIMESTAMP] - instances[schema.TIMESTAMP]).dt.total_seconds(),
        }
    ).dropna()
    expected = pairs.groupby(["a", "b"])["seconds"].agg(["count", "mean", "median"])
    ours = class_graph(neo4j_driver, name, "activity", "msg_id")
    assert set(ours) == set(expected.index)
    for pair, (count, mean, median) in ours.items():
        assert count == expected.loc[pair, "count"], pair
        assert (mean, median) == pytest.approx(tuple(expected.loc[pair, ["mean", "median"]]))


def test_df_c_in_cypher_equals_df_c_at_ingest(neo4j_driver, thesis_ekg, thesis_log, log_name):
    """A stored log aggregated again in Neo4j (cypher/ekg_aggregate_df_c.cypher) gets the DF_C
    the ingest computed in pandas, edge by edge."""
    name, _ = thesis_ekg
    build_ekg(
        neo4j_driver,
        thesis_log,
        log_name,
        entities=["robot", "msg_id"],
        aggregate=[],
        progress=False,
    )
    aggregate(neo4j_driver, log_name, "activity,robot")
    for entity_type in ("robot", "msg_id"):
        at_ingest = class_graph(neo4j_driver, name, "activity+robot", entity_type)
        in_cypher = class_graph(neo4j_driver, log_name, "activity+robot", entity_type)
        assert in_cypher.keys() == at_ingest.keys() and len(at_ingest) > 10
        for pair, (count, mean, median) in at_ingest.items():
            assert in_cypher[pair][0] == count, pair
            assert in_cypher[pair][1:] == pytest.approx((mean, median), abs=1e-6), pair


#: a robot exploring with in-progress samples, scanning, exploring again until its battery
#: runs low (the Explore aborted at that instant), then starting an Explore that never ends;
#: another robot moving twice. Seconds after 10:00.
SAMPLED = [
    (0, "explore", "start", "", "r1"),
    (1, "explore", "", "inprogress", "r1"),
    (2, "explore", "", "inprogress", "r1"),
    (3, "explore", "complete", "", "r1"),
    (4, "scan", "start", "", "r1"),
    (5, "scan", "complete", "", "r1"),
    (6, "explore", "start", "", "r1"),
    (7, "explore", "", "inprogress", "r1"),
    (8, "explore", "ate_abort", "", "r1"),
    (8, "low_battery", "instant", "", "r1"),
    (9, "explore", "start", "", "r1"),
    (1, "move", "start", "", "r2"),
    (2, "move", "", "inprogress", "r2"),
    (4, "move", "complete", "", "r2"),
    (5, "move", "start", "", "r2"),
    (6, "move", "complete", "", "r2"),
]


def test_df_c_and_class_counts_by_hand_keep_instances_and_samples_apart(
    neo4j_driver, log_name, tmp_path
):
    """Counted by hand from SAMPLED: each robot's consecutive activity instances (an
    instance counted once, by the event that ends it; samples and starts none), at ingest
    (pandas) and aggregated again in Neo4j (Cypher) alike."""
    rows = [
        f"2024-01-01T10:00:{second:02d}+00:00,{activity},{lifecycle},{state},{robot}"
        for second, activity, lifecycle, state, robot in SAMPLED
    ]
    path = tmp_path / "sampled.csv"
    path.write_text("\n".join(["time,activity,lifecycle,state,robot", *rows]) + "\n")
    build_ekg(
        neo4j_driver,
        read_csv(path),
        log_name,
        entities=["robot"],
        aggregate=["activity"],
        progress=False,
    )
    expected = {
        ("explore", "scan"): (1, 2.0, 2.0),
        ("scan", "explore"): (1, 3.0, 3.0),
        ("explore", "low_battery"): (1, 0.0, 0.0),
        ("move", "move"): (1, 2.0, 2.0),
    }
    assert class_graph(neo4j_driver, log_name, "activity", "robot") == expected
    aggregate(neo4j_driver, log_name, "activity")
    assert class_graph(neo4j_driver, log_name, "activity", "robot") == expected
    graph = discover_ekg(log_name, "activity", driver=neo4j_driver)
    counts = {
        node.label: (node.count, node.properties["samples"])
        for node in graph.nodes
        if node.kind != "entity"
    }
    assert counts == {"explore": (2, 3), "scan": (1, 0), "low_battery": (1, 0), "move": (2, 1)}


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
    for robot, part in instance_frame(thesis_log).groupby(schema.ROBOT):
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
