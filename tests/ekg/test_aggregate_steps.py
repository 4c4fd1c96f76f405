"""Aggregation steps on small graphs whose aggregates, lifted edges and attribute values are
counted by hand in the comments: every function, event and entity steps, where filters,
stacked steps and undo, and the CLI's verification table."""

from __future__ import annotations

import datetime as dt
import json

import pytest

from robotale.cli import main
from robotale.ekg.build import build_ekg
from robotale.ekg.connection import database
from robotale.ekg.spec import parse_spec
from robotale.ekg.steps import level_graph, list_steps, run_spec, undo
from robotale.errors import InputError
from robotale.eventlog.readers import read_csv

# Two robots; DF per robot: r1 e1 -> e2 -> e5, r2 e3 -> e4. Order o1 is in e1 and e3, o2 in e4.
SMALL = """case,activity,time,robot,parcel,battery,x,y,event_id
c1,move,2024-01-01T10:00:00Z,r1,o1,90,1,1,e1
c1,spray,2024-01-01T10:01:00Z,r1,,80,6,1,e2
c1,move,2024-01-01T10:02:00Z,r2,o1,70,1,6,e3
c1,spray,2024-01-01T10:03:00Z,r2,o2,60,6,6,e4
c1,move,2024-01-01T10:04:00Z,r1,,90,2,2,e5
"""


@pytest.fixture
def small(tmp_path, neo4j_driver, log_name) -> str:
    path = tmp_path / "small.csv"
    path.write_text(SMALL)
    build_ekg(neo4j_driver, read_csv(path), log_name, entities=["robot", "parcel"], progress=False)
    return log_name


def steps(*items: dict) -> list:
    return parse_spec({"steps": list(items)})


def aggregates(driver, log: str, step: int | None = None) -> dict[str, dict]:
    records, _, _ = driver.execute_query(
        "MATCH (a:Aggregate {log: $log}) WHERE $step IS NULL OR a.step = $step "
        "RETURN properties(a) AS a",
        log=log,
        step=step,
        database_=database(),
    )
    return {r["a"]["name"]: r["a"] for r in records}


def lifted(driver, log: str, kind: str) -> dict[tuple[str, str, str | None], int]:
    """Lifted edges of type ``kind`` by (source, target, entityType): aggregates by name,
    other nodes by id."""
    records, _, _ = driver.execute_query(
        f"MATCH (a)-[r:{kind}]->(b) WHERE r.step IS NOT NULL AND (a.log = $log OR b.log = $log) "
        "RETURN coalesce(a.name, a.id) AS a, coalesce(b.name, b.id) AS b, "
        "r.entityType AS t, r.count AS n",
        log=log,
        database_=database(),
    )
    return {(r["a"], r["b"], r["t"]): r["n"] for r in records}


def members(driver, log: str) -> dict[str, set[str]]:
    records, _, _ = driver.execute_query(
        "MATCH (m:AggregateMembers {log: $log}) UNWIND m.members AS member "
        "MATCH (a:Aggregate {log: $log, id: m.id}) "
        "OPTIONAL MATCH (e:Event {log: $log, id: member}) "
        "OPTIONAL MATCH (n:Entity {log: $log, type: a.type, id: member}) "
        "WITH a, coalesce(e, n) AS node WHERE node IS NOT NULL "
        "RETURN a.name AS a, collect(node.id) AS ids",
        log=log,
        database_=database(),
    )
    return {r["a"]: set(r["ids"]) for r in records}


def test_event_step_with_every_function(neo4j_driver, small):
    spec = steps(
        {
            "aggr_type": "EVENTS",
            "group_by": ["activity"],
            "attr_aggrs": [
                {"name": "battery", "function": f}
                for f in ("SUM", "AVG", "MIN", "MAX", "MINMAX", "MULTISET")
            ]
            + [{"name": "timestamp", "function": "MINMAX"}],
        }
    )
    [result] = run_spec(neo4j_driver, small, spec)
    # move: e1 e3 e5 (battery 90 70 90), spray: e2 e4 (80 60)
    found = aggregates(neo4j_driver, small)
    assert set(found) == {"move", "spray"}
    move, spray = found["move"], found["spray"]
    assert (move["count"], spray["count"]) == (3, 2)
    assert (move["battery_sum"], spray["battery_sum"]) == (250, 140)
    assert move["battery_avg"] == pytest.approx(250 / 3) and spray["battery_avg"] == 70
    assert (move["battery_min"], move["battery_max"]) == (70, 90)
    assert (spray["battery_min"], spray["battery_max"]) == (60, 80)
    assert move["battery_multiset"] == ["70:1", "90:2"]
    assert spray["battery_multiset"] == ["60:1", "80:1"]
    utc = dt.UTC
    assert move["timestamp_min"].to_native() == dt.datetime(2024, 1, 1, 10, 0, tzinfo=utc)
    assert move["timestamp_max"].to_native() == dt.datetime(2024, 1, 1, 10, 4, tzinfo=utc)
    assert (move["origin"], move["step"], move["id"], move["key"]) == (
        "Event",
        1,
        "1:move",
        ["activity"],
    )
    assert members(neo4j_driver, small) == {"move": {"e1", "e3", "e5"}, "spray": {"e2", "e4"}}
    # DF robot: e1->e2, e3->e4 (move->spray 2), e2->e5 (spray->move 1); parcel o1: e1->e3
    assert lifted(neo4j_driver, small, "DF") == {
        ("move", "spray", "robot"): 2,
        ("spray", "move", "robot"): 1,
        ("move", "move", "parcel"): 1,
    }
    # CORR: move -> r1 (e1, e5), r2 (e3), o1 (e1, e3); spray -> r1, r2, o2 (e4)
    assert lifted(neo4j_driver, small, "CORR") == {
        ("move", "r1", None): 2,
        ("move", "r2", None): 1,
        ("move", "o1", None): 2,
        ("spray", "r1", None): 1,
        ("spray", "r2", None): 1,
        ("spray", "o2", None): 1,
    }
    assert (result.initial_events, result.final_events) == (5, 0)
    assert (result.initial_entities, result.final_entities) == (4, 4)
    assert (result.aggregates, result.members) == (2, 5)


def test_entity_step_then_event_step_by_the_aggregated_entities(neo4j_driver, small):
    spec = steps(
        {"aggr_type": "ENTITIES", "ent_type": "robot", "group_by": ["type"],
         "attr_aggrs": [{"name": "id", "function": "MULTISET"}]},
        {"aggr_type": "EVENTS", "group_by": ["activity", "robot"], "where": "battery >= 70"},
    )  # fmt: skip
    first, second = run_spec(neo4j_driver, small, spec)
    robots = aggregates(neo4j_driver, small, 1)
    assert list(robots) == ["robot"]
    assert robots["robot"]["count"] == 2 and robots["robot"]["id_multiset"] == ["r1:1", "r2:1"]
    # battery >= 70: e1 move r1, e2 spray r1, e3 move r2, e5 move r1; the robots are one
    # aggregate now, so move|1:robot holds e1 e3 e5 and spray|1:robot holds e2.
    events = aggregates(neo4j_driver, small, 2)
    assert {n: a["count"] for n, a in events.items()} == {"move|1:robot": 3, "spray|1:robot": 1}
    assert events["move|1:robot"]["activity"] == "move"
    assert (first.initial_entities, first.final_entities) == (4, 2)
    assert (second.initial_events, second.final_events) == (5, 1)
    graph = level_graph(neo4j_driver, small, 2)
    corr = {(e["source"], e["target"]): e["count"] for e in graph["edges"] if e["type"] == "CORR"}
    # move e1 e3 e5 -> robots 3 times; spray e2 -> robots once
    assert corr == {("2:move|1:robot", "1:robot"): 3, ("2:spray|1:robot", "1:robot"): 1}
    df = {(e["source"], e["target"]): e["count"] for e in graph["edges"] if e["type"] == "DF"}
    # robot DF e1->e2 (move->spray), e2->e5 (spray->move), parcel o1 e1->e3 (move->move); e3->e4
    # leads to e4, which no step aggregated, so it is no edge between aggregates
    assert df == {
        ("2:move|1:robot", "2:spray|1:robot"): 1,
        ("2:spray|1:robot", "2:move|1:robot"): 1,
        ("2:move|1:robot", "2:move|1:robot"): 1,
    }
    # the event still on its own keeps its edges, lifted at its neighbours' level
    assert lifted(neo4j_driver, small, "DF")[("move|1:robot", "e4", "robot")] == 1
    assert lifted(neo4j_driver, small, "CORR")[("e4", "robot", None)] == 1
    assert level_graph(neo4j_driver, small, 1)["edges"] == []


def test_where_filters_split_a_grouping_over_steps(neo4j_driver, small):
    spec = steps(
        {"aggr_type": "EVENTS", "group_by": ["activity"],
         "where": "battery >= 80 and not activity = 'spray' or x in [6, 7] and y > 5"},
        {"aggr_type": "EVENTS", "group_by": ["robot"],
         "where": "timestamp < datetime('2024-01-01T10:04:00')"},
        {"aggr_type": "EVENTS", "group_by": ["activity"], "where": "parcel is null"},
    )  # fmt: skip
    results = run_spec(neo4j_driver, small, spec)
    # step 1: battery >= 80 and not spray: e1, e5 (move); or x in [6,7] and y > 5: e4 (spray)
    # step 2: before 10:04 and not yet aggregated: e2 (r1), e3 (r2)
    # step 3: no event left
    assert members(neo4j_driver, small) == {
        "move": {"e1", "e5"}, "spray": {"e4"}, "r1": {"e2"}, "r2": {"e3"},
    }  # fmt: skip
    assert [(r.initial_events, r.final_events, r.aggregates) for r in results] == [
        (5, 2, 2), (2, 0, 2), (0, 0, 0),
    ]  # fmt: skip


def test_stacked_steps_undo_as_units(neo4j_driver, small, graph_counts):
    before = graph_counts()
    first = steps({"aggr_type": "ENTITIES", "ent_type": "parcel", "group_by": ["type"]})
    run_spec(neo4j_driver, small, first)
    after_first = graph_counts()
    run_spec(neo4j_driver, small, steps(
        {"aggr_type": "EVENTS", "group_by": ["activity"], "where": "robot = 'r1'"},
        {"aggr_type": "EVENTS", "group_by": ["activity"]},
    ))  # fmt: skip
    # each step recorded complete, with its counts, by the run's one write at its end
    assert [(s["step"], s["status"], s["legacy"]) for s in list_steps(neo4j_driver, small)] == [
        (1, "complete", False), (2, "complete", False), (3, "complete", False)
    ]  # fmt: skip
    assert undo(neo4j_driver, small) == [3]
    assert set(aggregates(neo4j_driver, small)) == {"parcel", "move", "spray"}
    # step 3 took e3 and e4 (the events step 2 left); undone, they are free again
    assert members(neo4j_driver, small) == {
        "parcel": {"o1", "o2"}, "move": {"e1", "e5"}, "spray": {"e2"}
    }  # fmt: skip
    assert undo(neo4j_driver, small, 2) == [2]
    assert graph_counts() == after_first
    assert members(neo4j_driver, small) == {"parcel": {"o1", "o2"}}
    with pytest.raises(InputError, match="no aggregation step 5"):
        undo(neo4j_driver, small, 5)
    assert undo(neo4j_driver, small, 1) == [1]
    assert graph_counts() == before
    assert members(neo4j_driver, small) == {}
    assert undo(neo4j_driver, small) == []


def test_steps_of_an_earlier_version_are_undone_with_their_marks(neo4j_driver, small, graph_counts):
    before = graph_counts()
    run_spec(neo4j_driver, small, steps(
        {"aggr_type": "ENTITIES", "ent_type": "parcel", "group_by": ["type"]},
    ))  # fmt: skip
    # the form an earlier version left: no member list, each member marked with its aggregate
    neo4j_driver.execute_query(
        "MATCH (m:AggregateMembers {log: $log}) DELETE m "
        "WITH count(*) AS done MATCH (n:Entity {log: $log, type: 'parcel'}) "
        "SET n._aggregate = '1:parcel'",
        log=small,
        database_=database(),
    )
    again = steps({"aggr_type": "EVENTS", "group_by": ["activity"]})
    with pytest.raises(InputError, match=r"step\(s\) 1 of log .* earlier version.*--undo 1"):
        run_spec(neo4j_driver, small, again)
    assert undo(neo4j_driver, small) == [1]
    assert graph_counts() == before
    marked, _, _ = neo4j_driver.execute_query(
        "MATCH (n {log: $log}) WHERE n._aggregate IS NOT NULL RETURN count(n) AS n",
        log=small,
        database_=database(),
    )
    assert marked[0]["n"] == 0
    run_spec(neo4j_driver, small, again)  # the log aggregates as it did before
    assert set(aggregates(neo4j_driver, small)) == {"move", "spray"}


def test_bad_steps_are_refused_before_anything_is_written(neo4j_driver, small, graph_counts):
    before = graph_counts()
    cases = [
        ({"aggr_type": "EVENTS", "group_by": ["speed"]}, "no property 'speed'"),
        ({"aggr_type": "EVENTS", "group_by": ["activity"], "where": "speed > 1"}, "names 'speed'"),
        ({"aggr_type": "EVENTS", "group_by": ["activity"], "where": "battery >"}, "at its end"),
        ({"aggr_type": "EVENTS", "group_by": ["activity"],
          "where": "x = 1; MATCH (n) DETACH DELETE n"}, "cannot be read at character 6"),
        ({"aggr_type": "ENTITIES", "ent_type": "tractor", "group_by": ["type"]},
         "no entities of type"),
        ({"aggr_type": "EVENTS", "group_by": ["activity"],
          "attr_aggrs": [{"name": "activity", "function": "SUM"}]}, "needs numbers"),
    ]  # fmt: skip
    for step, message in cases:
        with pytest.raises(InputError, match=message):
            run_spec(neo4j_driver, small, steps(step))
    # a good first step is not run when a later one is refused
    good = {"aggr_type": "EVENTS", "group_by": ["activity"]}
    with pytest.raises(InputError, match="step 2"):
        run_spec(neo4j_driver, small, steps(good, cases[0][0]))
    assert graph_counts() == before


def test_cli_prints_the_verification_table(tmp_path, capsys, neo4j_driver, small):
    spec = tmp_path / "spec.yaml"
    spec.write_text(
        "steps:\n"
        "  - {aggr_type: ENTITIES, ent_type: robot, group_by: [type]}\n"
        "  - {aggr_type: EVENTS, group_by: [activity], where: 'battery < 85'}\n"
    )
    assert main(["aggregate", small, "--spec", str(spec), "--json"]) == 0
    table = json.loads(capsys.readouterr().out)
    counts = [
        {
            k: row[k]
            for k in ("initial_events", "final_events", "initial_entities", "final_entities")
        }
        for row in table
    ]
    # robots r1 r2 collapse (4 -> 2 entities); battery < 85: e2 e3 e4
    assert counts == [
        {"initial_events": 5, "final_events": 5, "initial_entities": 4, "final_entities": 2},
        {"initial_events": 5, "final_events": 2, "initial_entities": 2, "final_entities": 2},
    ]
    assert main(["aggregate", small, "--undo"]) == 0
    assert "Undid aggregation step 2" in capsys.readouterr().out
    bad = tmp_path / "bad.yaml"
    bad.write_text("steps:\n  - {aggr_type: EVENT, group_by: [activity]}\n")
    assert main(["aggregate", small, "--spec", str(bad)]) == 1
    assert "needs aggr_type ENTITIES or EVENTS" in capsys.readouterr().err
    assert main(["aggregate", small, "--undo", "x"]) == 1
    assert main(["aggregate", "no such log", "--undo"]) == 1


def test_a_deleted_log_takes_its_aggregates_along(neo4j_driver, small, graph_counts):
    from robotale.ekg.logs import delete_log

    before = graph_counts()
    run_spec(neo4j_driver, small, steps({"aggr_type": "EVENTS", "group_by": ["activity"]}))
    delete_log(neo4j_driver, small)
    after = graph_counts()
    for kind in ("node:Aggregate", "node:AggregationStep"):
        assert after.get(kind, 0) <= before.get(kind, 0)


def test_a_step_that_fails_while_writing_leaves_nothing(neo4j_driver, small, graph_counts):
    from robotale.errors import ServerError

    before = graph_counts()
    # A node in the way of the step's second aggregate: Neo4j refuses to create that one
    # (the aggregate key is unique) after the first is written.
    neo4j_driver.execute_query(
        "CREATE (:Aggregate {log: $log, step: 1, id: '1:spray'})", log=small, database_=database()
    )
    spec = steps({"aggr_type": "EVENTS", "group_by": ["activity"]})
    with pytest.raises(
        ServerError, match=r"Aggregation step 1 of .* failed .*nothing of it was kept"
    ):
        run_spec(neo4j_driver, small, spec)
    # the undo takes the node in the way along: it stood where step 1's aggregates go
    assert graph_counts() == before
    assert list_steps(neo4j_driver, small) == []


def test_band_grid_and_region_keys(neo4j_driver, small):
    spec = steps(
        {"aggr_type": "EVENTS", "where": "robot = 'r1'",
         "group_by": [{"band": {"property": "battery", "width": 25}},
                      {"grid": {"size": 5}, "as": "tile"}]},
        {"aggr_type": "EVENTS",
         "group_by": [{"regions": {"areas": {"left": {"box": [0, 0, 5, 10]},
                                             "right": [[5, 0], [10, 0], [10, 10], [5, 10]]}}}]},
    )  # fmt: skip
    run_spec(neo4j_driver, small, spec)
    # r1: e1 (90, at 1,1), e2 (80, at 6,1), e5 (90, at 2,2): bands 75 75 75, tiles 0,0 1,0 0,0
    found = aggregates(neo4j_driver, small, 1)
    assert {n: a["count"] for n, a in found.items()} == {"75.0|0,0": 2, "75.0|1,0": 1}
    assert found["75.0|1,0"]["battery_band"] == 75.0 and found["75.0|1,0"]["tile"] == "1,0"
    # r2: e3 at 1,6 (left), e4 at 6,6 (right)
    assert members(neo4j_driver, small) == {
        "75.0|0,0": {"e1", "e5"}, "75.0|1,0": {"e2"}, "left": {"e3"}, "right": {"e4"},
    }  # fmt: skip


ROBOTS = {"aggr_type": "ENTITIES", "ent_type": "robot", "group_by": ["type"]}
ACTIVITIES = {"aggr_type": "EVENTS", "group_by": ["activity"]}
# step 1 alone: every event's CORR edge to its robot goes to the robots' aggregate
ROBOTS_ALONE = {(e, "robot", None): 1 for e in ("e1", "e2", "e3", "e4", "e5")}


def test_steps_run_together_write_the_edges_of_the_level_they_end_at(
    neo4j_driver, small, graph_counts
):
    run_spec(neo4j_driver, small, steps(ROBOTS))
    alone = {kind: lifted(neo4j_driver, small, kind) for kind in ("CORR", "DF", "COMM")}
    assert alone["CORR"] == ROBOTS_ALONE
    counts = graph_counts()
    undo(neo4j_driver, small)
    run_spec(neo4j_driver, small, steps(ROBOTS, ACTIVITIES))
    # together: no edge from an event to the robots, since step 2 holds every event; move
    # e1 e3 e5 -> robots 3 times, o1 (e1, e3) twice; spray e2 e4 -> robots twice, o2 (e4) once
    assert lifted(neo4j_driver, small, "CORR") == {
        ("move", "robot", None): 3,
        ("move", "o1", None): 2,
        ("spray", "robot", None): 2,
        ("spray", "o2", None): 1,
    }
    # undoing step 2 gives step 1 the edges it has when run alone
    assert undo(neo4j_driver, small) == [2]
    assert {kind: lifted(neo4j_driver, small, kind) for kind in alone} == alone
    assert graph_counts() == counts


def test_a_later_step_that_fails_leaves_the_earlier_ones_as_if_run_alone(neo4j_driver, small):
    from robotale.errors import ServerError

    neo4j_driver.execute_query(
        "CREATE (:Aggregate {log: $log, step: 2, id: '2:spray'})", log=small, database_=database()
    )
    with pytest.raises(ServerError, match=r"Aggregation step 2 of .* failed"):
        run_spec(neo4j_driver, small, steps(ROBOTS, ACTIVITIES))
    # the step before the failing one is kept, and recorded complete before the error
    assert [(s["step"], s["status"]) for s in list_steps(neo4j_driver, small)] == [(1, "complete")]
    assert lifted(neo4j_driver, small, "CORR") == ROBOTS_ALONE


def test_a_run_on_a_log_being_written_is_refused_and_the_lock_given_back(
    neo4j_driver, small, graph_counts
):
    from robotale.ekg.writelock import LogBusy, holder, log_write_lock

    before = graph_counts()
    spec = steps(ACTIVITIES)
    busy = pytest.raises(LogBusy, match="aggregating it now is refused")
    with log_write_lock(neo4j_driver, small, "writing"), busy:  # another writer of the log
        run_spec(neo4j_driver, small, spec)
    assert graph_counts() == before
    with pytest.raises(InputError, match="no log named"):  # the lock taken, then given back
        run_spec(neo4j_driver, "no such log", spec)
    assert holder(neo4j_driver, "no such log") is None
    run_spec(neo4j_driver, small, spec)  # the run's lock given back: undo takes it again
    assert holder(neo4j_driver, small) is None
    assert undo(neo4j_driver, small) == [1]
