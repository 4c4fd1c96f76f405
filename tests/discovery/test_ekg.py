"""EKG discovery against the real Neo4j the tests start."""

import json
import re
import uuid

import pandas as pd
import pm4py
import pytest
from instance_frames import instance_frame

from robotale.cli import main
from robotale.discovery import discover_ekg
from robotale.discovery.ekg import COMM, read_stored_log
from robotale.discovery.ekg_table import table_class_graph
from robotale.ekg import build_ekg
from robotale.ekg.logs import delete_log
from robotale.errors import InputError
from robotale.eventlog.schema import ACTIVITY, CASE, EVENT_ID, MSG_ID, ROBOT, TIMESTAMP


@pytest.fixture(scope="module")
def stored(neo4j_driver, thesis_log):
    """The thesis log stored once for this module, with the activity classes only."""
    name = f"test_discovery_{uuid.uuid4().hex[:8]}"
    build_ekg(
        neo4j_driver, thesis_log, name, entities=["robot", "msg_id"], aggregate=["activity"],
        progress=False,
    )  # fmt: skip
    yield name
    delete_log(neo4j_driver, name)


@pytest.fixture(scope="module")
def by_robot(stored, neo4j_driver):
    """activity+robot classes: built on demand, the log was stored with activity only."""
    return discover_ekg(stored, "activity,robot", driver=neo4j_driver)


def same_graph(computed: dict, stored: dict) -> None:
    """The class graph computed from the event table is the stored graph's: the same nodes
    and edges in the same order, the seconds equal to rounding (Neo4j adds them up in
    another order)."""
    assert computed["info"] == stored["info"]
    for part in ("nodes", "edges"):
        assert len(computed[part]) == len(stored[part])
        for mine, theirs in zip(computed[part], stored[part], strict=True):
            assert mine["durations"] == pytest.approx(theirs["durations"], rel=1e-9, abs=1e-9)
            assert {**mine, "durations": None} == {**theirs, "durations": None}


def test_the_table_computes_the_graph_neo4j_holds(by_robot, stored, neo4j_driver, thesis_log):
    """The class graph from the event table against the one read from Neo4j: classes built
    on demand by Cypher (activity+robot) and with the log (activity), one entity type or
    both."""
    same_graph(
        table_class_graph(stored, thesis_log, ["activity", "robot"], ["robot", "msg_id"]).to_dict(),
        by_robot.to_dict(),
    )
    by_activity = discover_ekg(stored, "activity", ["msg_id"], driver=neo4j_driver)
    computed = table_class_graph(stored, thesis_log, ["activity"], ["msg_id"])
    same_graph(computed.to_dict(), by_activity.to_dict())
    assert any(e.entity_type == COMM for e in computed.edges)


def test_per_robot_df_counts_equal_pm4py(by_robot, thesis_log):
    """DF_C aggregated in Neo4j for a key the log was not stored with, against pm4py's DFG of
    each robot's activity instances."""
    for robot, events in instance_frame(thesis_log).groupby(ROBOT):
        expected, _, _ = pm4py.discover_dfg(events.assign(**{"case:concept:name": robot}))
        activity = {n.id: n.properties.get("activity") for n in by_robot.nodes}
        edges = {
            (activity[e.source], activity[e.target]): e.count
            for e in by_robot.edges
            if e.entity_type == "robot" and by_robot.node(e.source).robot == robot
        }
        assert edges == dict(expected), robot


def test_classes_count_their_instances_and_events_apart(by_robot, thesis_log):
    events = thesis_log.groupby([ACTIVITY, ROBOT]).size()
    # an instance is counted once, by the event that ends it (the thesis has no samples)
    ends = thesis_log[thesis_log["lifecycle:transition"] != "start"]
    instances = ends.groupby([ACTIVITY, ROBOT]).size().reindex(events.index, fill_value=0)
    classes = [n for n in by_robot.nodes if n.kind == "activity"]
    assert len(classes) == len(events)
    for node in classes:
        key = (node.properties["activity"], node.robot)
        assert node.count == instances[key]
        assert node.properties["events"] == events[key] and node.properties["samples"] == 0
    assert by_robot.node("explore|drone").label == "explore (drone)"
    assert by_robot.info["class_type"] == "activity+robot"


def test_comm_edges_count_messages_between_classes(by_robot, thesis_log):
    # the thesis' convention: "!" sends, "?" receives (select_closest_tractor carries the
    # msg_id of the message it prepares without passing it on)
    names = thesis_log[ACTIVITY]
    columns = [MSG_ID, ACTIVITY, ROBOT]
    sends = thesis_log[names.str.endswith("!")][columns].drop_duplicates()
    receives = thesis_log[names.str.endswith("?")][columns].drop_duplicates()
    pairs = sends.merge(receives, on=MSG_ID, suffixes=("_s", "_r"))
    pairs["source"] = pairs[f"{ACTIVITY}_s"] + "|" + pairs[f"{ROBOT}_s"]
    pairs["target"] = pairs[f"{ACTIVITY}_r"] + "|" + pairs[f"{ROBOT}_r"]
    expected = pairs.groupby(["source", "target"])[MSG_ID].nunique().to_dict()
    comm = {(e.source, e.target): e.count for e in by_robot.edges if e.entity_type == COMM}
    assert comm == expected
    assert comm[("weed_position!|drone", "weed_position?|tractor_1")] > 0


def test_entry_nodes_join_each_robot_to_its_first_class(by_robot, thesis_log):
    entries = {(e.source, e.target) for e in by_robot.edges if e.source.startswith("robot:")}
    firsts = thesis_log.groupby(ROBOT).first()
    assert entries == {(f"robot:{r}", f"{row[ACTIVITY]}|{r}") for r, row in firsts.iterrows()}
    assert by_robot.node("robot:drone").kind == "entity"
    # 421 messages: one entry node stands for all of them
    messages = by_robot.node("msg_id:*")
    assert messages.count == thesis_log[MSG_ID].nunique() == 421
    into = sum(e.count for e in by_robot.edges if e.source == "msg_id:*")
    assert into == 421


def test_each_run_begins_an_entity_anew(neo4j_driver, thesis_log, log_name):
    # The thesis log twice, as two runs: each robot begins once per run.
    twice = pd.concat([thesis_log.assign(case="r1"), thesis_log.assign(case="r2")])
    twice = twice.drop(columns=CASE).rename(columns={"case": CASE})
    twice[EVENT_ID] = [f"e{i}" for i in range(len(twice))]
    build_ekg(neo4j_driver, twice, log_name, entities=["robot"], progress=False)
    graph = discover_ekg(log_name, "activity,robot", ["robot"], driver=neo4j_driver)
    entries = {(e.source, e.target): e.count for e in graph.edges if e.source.startswith("robot:")}
    firsts = thesis_log.groupby(ROBOT).first()
    assert entries == {(f"robot:{r}", f"{row[ACTIVITY]}|{r}"): 2 for r, row in firsts.iterrows()}


def test_a_log_stored_without_begins_edges_gets_them_on_first_discovery(
    neo4j_driver, thesis_log, log_name
):
    # Earlier versions of robotale stored no BEGINS edges and computed entry nodes on reading.
    build_ekg(neo4j_driver, thesis_log, log_name, entities=["robot"], progress=False)
    neo4j_driver.execute_query("MATCH (:Entity {log: $log})-[b:BEGINS]->() DELETE b", log=log_name)
    graph = discover_ekg(log_name, "activity", ["robot"], driver=neo4j_driver)
    entries = {(e.source, e.target): e.count for e in graph.edges if e.source.startswith("robot:")}
    firsts = thesis_log.groupby(ROBOT).first()
    assert entries == {(f"robot:{r}", row[ACTIVITY]): 1 for r, row in firsts.iterrows()}


def test_choose_the_entity_types_to_show(stored, neo4j_driver):
    graph = discover_ekg(stored, "activity", ["msg_id"], driver=neo4j_driver)
    assert {e.entity_type for e in graph.edges} == {"msg_id", COMM}
    assert graph.node("explore").robot == "drone"  # one robot explores
    assert graph.node("move").robot is None and graph.node("move").robots == [
        "drone",
        "tractor_1",
        "tractor_2",
    ]


def test_bad_requests_name_what_is_wrong(stored, neo4j_driver):
    with pytest.raises(InputError, match=r"no entity type 'case'.*robot, msg_id"):
        discover_ekg(stored, "activity", ["case"], driver=neo4j_driver)
    with pytest.raises(InputError, match="no log named 'nowhere'"):
        discover_ekg("nowhere", driver=neo4j_driver)
    with pytest.raises(InputError, match="no property 'colour'"):
        discover_ekg(stored, "activity,colour", driver=neo4j_driver)


def test_a_stored_log_reads_back_as_it_went_in(stored, neo4j_driver, thesis_log):
    back = read_stored_log(stored, driver=neo4j_driver)
    assert len(back) == len(thesis_log)
    assert back[TIMESTAMP].equals(thesis_log[TIMESTAMP].astype(back[TIMESTAMP].dtype))
    assert back[ACTIVITY].tolist() == thesis_log[ACTIVITY].tolist()
    assert back[ROBOT].tolist() == thesis_log[ROBOT].tolist()
    assert str(back[TIMESTAMP].dt.tz) == str(thesis_log[TIMESTAMP].dt.tz)


def test_command_line_writes_json_and_svg(stored, neo4j_server, tmp_path, capsys):
    out, svg = tmp_path / "agri_ekg.json", tmp_path / "agri_ekg.svg"
    code = main([
        "discover", "ekg", "--log", stored, "--aggregate", "activity,robot",
        "--entities", "robot,msg_id", "--out", str(out), "--svg", str(svg),
    ])  # fmt: skip
    assert code == 0
    data = json.loads(out.read_text())
    assert data["kind"] == "ekg" and {"robot", "msg_id", COMM} <= {
        e["entity_type"] for e in data["edges"]
    }
    assert "explore (drone)" in re.findall(r"<text[^>]*>(.*?)</text>", svg.read_text())
    assert "EKG:" in capsys.readouterr().out


def test_samples_are_no_instances(neo4j_driver, tmp_path):
    """A drone explores twice (each a start and a completion) with 5 in-progress samples in
    between, and once ends an explore aborted. By hand: 3 explore instances, 5 samples, 11
    events; land 1 instance."""
    rows = ["case,robot,activity,lifecycle,state,time,battery"]
    at = "2024-01-01T10:00:{:02d}Z".format
    rows += [f"1,drone,explore,start,,{at(0)},90", f"1,drone,explore,complete,,{at(5)},88"]
    rows += [f"1,drone,explore,start,,{at(6)},88"]
    rows += [f"1,drone,explore,none,inprogress,{at(t)},{88 - t / 10}" for t in (7, 8, 9, 10, 11)]
    rows += [f"1,drone,explore,complete,,{at(12)},86", f"1,drone,explore,start,,{at(13)},86"]
    rows += [f"1,drone,explore,ate_abort,,{at(14)},85"]
    rows += [f"1,drone,land,start,,{at(15)},85", f"1,drone,land,complete,,{at(16)},85"]
    path = tmp_path / "samples.csv"
    path.write_text("\n".join(rows) + "\n")
    from robotale.eventlog.readers import read_log

    name = f"test_samples_{uuid.uuid4().hex[:8]}"
    build_ekg(neo4j_driver, read_log(path), name, entities=["robot"], aggregate=["activity"],
              progress=False)  # fmt: skip
    try:
        graph = discover_ekg(name, "activity", driver=neo4j_driver)
        explore = graph.node("explore")
        assert explore.count == 3
        same_graph(
            table_class_graph(name, read_log(path), ["activity"], ["robot"]).to_dict(),
            graph.to_dict(),
        )
        assert (explore.properties["samples"], explore.properties["events"]) == (5, 11)
        assert graph.node("land").count == 1
    finally:
        delete_log(neo4j_driver, name)


def test_discover_bpmn_of_a_stored_log_is_the_files(
    stored, neo4j_server, thesis_csv, tmp_path, capsys
):
    """``discover bpmn --log NAME --robot-type Tractor`` writes what the same command writes
    from the file the log was stored from: one pool, the tractors'."""
    from_log, from_file = tmp_path / "log.bpmn", tmp_path / "file.bpmn"
    common = ["--robot-type", "Tractor", "--out"]
    assert main(["discover", "bpmn", "--log", stored, *common, str(from_log)]) == 0
    assert main(["discover", "bpmn", str(thesis_csv), *common, str(from_file)]) == 0
    printed = capsys.readouterr().out
    assert "pool Tractor (tractor_1, tractor_2)" in printed and "pool Drone" not in printed
    assert from_log.read_text(encoding="utf-8") == from_file.read_text(encoding="utf-8")
    assert re.findall(r'<bpmn:participant [^>]*name="([^"]*)"', from_file.read_text()) == [
        "Tractor"
    ]
