import json

import pandas as pd
import pm4py
import pytest
from pm4py.objects.log.util import interval_lifecycle

from robotale.discovery import LogFilter, ProcessGraph, discover_dfg
from robotale.discovery.graph import END_NODE, START_NODE
from robotale.errors import InputError
from robotale.eventlog.schema import ACTIVITY, CASE, LIFECYCLE, ROBOT, ROBOT_TYPE, STATE, TIMESTAMP


def pm4py_interval_dfg(log: pd.DataFrame):
    """pm4py's own route: lifecycle log -> interval log (msg_id pairs a start with its
    complete) -> DFG, on pm4py's EventLog objects rather than on a DataFrame."""
    event_log = pm4py.convert_to_event_log(log.assign(**{"concept:instance": log["msg_id"]}))
    intervals = interval_lifecycle.to_interval(event_log)
    return intervals, *pm4py.discover_dfg(intervals)


def test_drone_dfg_matches_pm4py(thesis_log):
    drone = thesis_log[thesis_log[ROBOT] == "drone"]
    _, expected, starts, ends = pm4py_interval_dfg(drone)

    graph = discover_dfg(thesis_log, LogFilter(robots=["drone"]))

    arcs = {
        k: v for k, v in graph.edge_counts().items() if START_NODE not in k and END_NODE not in k
    }
    assert arcs == dict(expected)
    assert {b: n for (a, b), n in graph.edge_counts().items() if a == START_NODE} == starts
    assert {a: n for (a, b), n in graph.edge_counts().items() if b == END_NODE} == ends
    # the thesis' figure 7.4: take off, explore, weed found, messages ... land
    assert ("takeoff", "explore") in arcs and ("move", "land") in arcs
    assert graph.node("explore").robot == "drone"


def test_edge_durations_are_waits_between_activities(thesis_log):
    drone = thesis_log[thesis_log[ROBOT] == "drone"]
    intervals, *_ = pm4py_interval_dfg(drone)
    # by hand: next start minus this completion, zero when the two overlap
    waits: dict[tuple[str, str], list[float]] = {}
    for trace in intervals:
        for a, b in zip(trace, list(trace)[1:], strict=False):
            gap = (max(b["start_timestamp"], a[TIMESTAMP]) - a[TIMESTAMP]).total_seconds()
            waits.setdefault((a[ACTIVITY], b[ACTIVITY]), []).append(gap)

    graph = discover_dfg(drone)

    for edge in graph.edges:
        if edge.source == START_NODE or edge.target == END_NODE:
            continue
        values = waits[(edge.source, edge.target)]
        assert edge.durations["mean"] == pytest.approx(sum(values) / len(values), abs=1e-6)
        assert edge.durations["median"] == pytest.approx(pd.Series(values).median(), abs=1e-6)


def test_node_counts_and_durations_by_hand():
    log = make_log(
        [
            ("c1", "r1", "a", "start", 0),
            ("c1", "r1", "a", "complete", 4),
            ("c1", "r1", "b", "start", 5),
            ("c1", "r1", "b", "complete", 6),
            ("c2", "r1", "a", "start", 0),
            ("c2", "r1", "a", "complete", 2),
            ("c2", "r1", "c", "start", 10),  # never completes
        ]
    )
    graph = discover_dfg(log)
    assert graph.node("a").count == 2
    assert graph.node("a").durations == {"mean": 3.0, "median": 3.0}
    assert graph.node("c").count == 0 and graph.node("c").properties["unfinished"] == 1
    assert graph.edge_counts() == {
        ("a", "b"): 1,
        (START_NODE, "a"): 2,
        ("b", END_NODE): 1,
        ("a", END_NODE): 1,
    }
    assert graph.node(START_NODE).count == 2 and graph.node(END_NODE).count == 2
    assert graph.info["cases"] == 2


def test_inprogress_rows_never_create_edges():
    rows = [
        ("c1", "r1", "a", "start", 0),
        ("c1", "r1", "a", "complete", 4),
        ("c1", "r1", "b", "start", 5),
        ("c1", "r1", "b", "complete", 9),
    ]
    plain = make_log(rows)
    progress = make_log([("c1", "r1", "b", "none", 7), ("c1", "r1", "a", "none", 3)])
    progress[STATE] = "inprogress"
    with_progress = pd.concat([plain.assign(**{STATE: "none"}), progress], ignore_index=True)
    with_progress = with_progress.sort_values(TIMESTAMP, kind="stable")

    assert discover_dfg(with_progress).edge_counts() == discover_dfg(plain).edge_counts()
    assert discover_dfg(with_progress).node("b").count == 1


def test_concurrent_robots_pair_their_own_activities():
    # two robots run "move" at overlapping times in one case; each start pairs with its own
    # robot's completion, so both instances last 10 s
    log = make_log(
        [
            ("c1", "r1", "move", "start", 0),
            ("c1", "r2", "move", "start", 5),
            ("c1", "r1", "move", "complete", 10),
            ("c1", "r2", "move", "complete", 15),
        ]
    )
    assert discover_dfg(log).node("move").durations["mean"] == 10.0


def test_filters_case_robot_type_window_activity():
    log = make_log(
        [
            ("c1", "drone", "takeoff", "start", 0),
            ("c1", "drone", "takeoff", "complete", 1),
            ("c1", "tractor_1", "move", "start", 2),
            ("c1", "tractor_1", "move", "complete", 3),
            ("c1", "drone", "land", "start", 4),
            ("c1", "drone", "land", "complete", 5),
            ("c2", "drone", "takeoff", "start", 0),
            ("c2", "drone", "takeoff", "complete", 1),
        ]
    )
    log[ROBOT_TYPE] = log[ROBOT].map({"drone": "Drone", "tractor_1": "Tractor"})

    assert discover_dfg(log, LogFilter(cases=["c2"])).info["cases"] == 1
    tractors = discover_dfg(log, LogFilter(robot_types=["Tractor"]))
    assert {n.id for n in tractors.nodes if n.kind == "activity"} == {"move"}
    window = LogFilter(start=log[TIMESTAMP].min() + pd.Timedelta(seconds=2), cases=["c1"])
    assert ("move", "land") in discover_dfg(log, window).edge_counts()
    projected = discover_dfg(log, LogFilter(activities=["takeoff", "land"], cases=["c1"]))
    assert ("takeoff", "land") in projected.edge_counts()
    naive_end = str((log[TIMESTAMP].min() + pd.Timedelta(seconds=1)).tz_localize(None))
    early = discover_dfg(log, LogFilter(end=naive_end, cases=["c1"]))
    assert {n.id for n in early.nodes if n.kind == "activity"} == {"takeoff"}


def test_filter_that_matches_nothing_names_the_value(thesis_log):
    with pytest.raises(InputError, match=r"robot drne; .*drone, tractor_1, tractor_2"):
        discover_dfg(thesis_log, LogFilter(robots=["drne"]))
    with pytest.raises(InputError, match="no event lies between"):
        discover_dfg(thesis_log, LogFilter(start="2030-01-01"))
    with pytest.raises(InputError, match="'robot_type' column"):
        discover_dfg(thesis_log, LogFilter(robot_types=["Drone"]))
    with pytest.raises(InputError, match="not a date"):
        discover_dfg(thesis_log, LogFilter(end="yesterday-ish"))


def test_graph_is_json_and_round_trips(thesis_log):
    graph = discover_dfg(thesis_log)
    text = graph.to_json()
    data = json.loads(text)
    assert {"id", "label", "robot", "count"} <= set(data["nodes"][0])
    assert {"source", "target", "label", "entity_type", "count", "durations"} <= set(
        data["edges"][0]
    )
    assert ProcessGraph.from_dict(data).to_dict() == data
    # the whole MRS, flattened: every robot's activities appear (thesis figure 7.5)
    assert set(data["info"]["robots"]) == {"drone", "tractor_1", "tractor_2"}
    assert graph.node("cut_grass").robots == ["tractor_1", "tractor_2"]


def make_log(rows) -> pd.DataFrame:
    """A canonical log from (case, robot, activity, lifecycle, seconds) rows."""
    base = pd.Timestamp("2024-01-01T10:00:00+00:00")
    log = pd.DataFrame(rows, columns=[CASE, ROBOT, ACTIVITY, LIFECYCLE, "seconds"])
    log[TIMESTAMP] = base + pd.to_timedelta(log.pop("seconds"), unit="s")
    return log
