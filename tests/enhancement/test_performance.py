import pandas as pd
import pm4py
import pytest
from pm4py.objects.log.util import interval_lifecycle

from robotale.enhancement import performance_perspective
from robotale.eventlog.schema import ROBOT


@pytest.fixture
def two_cases(events):
    rows = [
        ("1", "r1", "a", "start", 0),
        ("1", "r1", "a", "complete", 10),
        ("1", "r1", "b", "start", 14),
        ("1", "r1", "b", "complete", 20),
        ("1", "r2", "c", "start", 5),
        ("1", "r2", "c", "complete", 30),
        ("2", "r1", "a", "start", 0),
        ("2", "r1", "a", "complete", 20),
        ("2", "r1", "b", "start", 20),
        ("2", "r1", "b", "complete", 22),
    ]
    return events(
        *[
            {"case": c, "robot": r, "activity": a, "lifecycle": lc, "t": t}
            for c, r, a, lc, t in rows
        ]
    )


def test_durations_waits_and_cases_by_hand(two_cases):
    result = performance_perspective(two_cases)
    durations = result.tables["activities"].set_index("activity")
    assert durations.loc["a", "mean"] == 15.0 and durations.loc["a", "max"] == 20.0
    assert durations.loc["c", "count"] == 1
    waiting = result.tables["waiting"]
    # r1 waits 4 s between a and b in case 1 and 0 s in case 2; r2's c is not r1's successor
    assert list(waiting[["source", "target"]].itertuples(index=False, name=None)) == [("a", "b")]
    assert waiting.iloc[0]["mean"] == 2.0 and waiting.iloc[0]["max"] == 4.0
    cases = result.tables["cases"].set_index("case")
    assert cases.loc["1", "duration"] == 30.0 and cases.loc["2", "duration"] == 22.0
    assert result.summary["slowest_transition"] == "a -> b (r1)"


def test_drill_down_to_one_activity(two_cases):
    result = performance_perspective(two_cases, activity="c")
    assert list(result.tables["activities"]["activity"]) == ["c"]
    assert list(result.tables["cases"]["case"]) == ["1"]
    assert result.tables["waiting"].empty
    assert not performance_perspective(two_cases, activity="zzz").has_data


def test_thesis_service_times_equal_pm4py(thesis_log):
    drone = thesis_log[thesis_log[ROBOT] == "drone"]
    event_log = pm4py.convert_to_event_log(drone.assign(**{"concept:instance": drone["msg_id"]}))
    intervals = pm4py.convert_to_dataframe(interval_lifecycle.to_interval(event_log))
    expected = pm4py.get_service_time(intervals, start_timestamp_key="start_timestamp")

    table = performance_perspective(thesis_log, robot="drone").tables["activities"]

    assert dict(zip(table["activity"], table["mean"], strict=True)) == pytest.approx(expected)


def test_figures_and_json(two_cases):
    result = performance_perspective(two_cases)
    assert set(result.figures) == {"durations", "waiting", "cases"}
    data = result.to_dict()
    assert data["tables"]["cases"][0]["start"].startswith("2024-01-01T10:00:00")
    assert isinstance(pd.Timestamp(data["tables"]["cases"][0]["end"]), pd.Timestamp)


def test_working_and_waiting_time_are_kept_apart(two_cases):
    robots = performance_perspective(two_cases).tables["robots"].set_index(["case", "robot"])
    # by hand from the fixture: r1 works 10 + 6 s and waits 4 s in case 1; r2 works 25 s
    log = two_cases.assign(t=(two_cases["time:timestamp"] - two_cases["time:timestamp"].min()))
    seconds = log.pivot_table(
        index=["case:concept:name", "robot", "concept:name"],
        columns="lifecycle:transition",
        values="t",
        aggfunc="first",
    ).apply(lambda col: col.dt.total_seconds())
    work = (seconds["complete"] - seconds["start"]).groupby(level=[0, 1]).sum()
    assert robots["working"].to_dict() == work.to_dict()
    assert robots.loc[("1", "r1"), "waiting"] == seconds.loc[("1", "r1", "b"), "start"] - 10
    assert robots["waiting"].sum() == 4.0
    cases = performance_perspective(two_cases).tables["cases"].set_index("case")
    assert cases.loc["1", "working"] + cases.loc["1", "waiting"] == 10 + 6 + 25 + 4


def test_a_completion_without_its_start_is_never_waiting(events):
    # only completions: the 300 s before navigate completes is its own work, not a wait
    log = events(
        {"case": "1", "robot": "r", "activity": "plan", "lifecycle": "complete", "t": 10},
        {"case": "1", "robot": "r", "activity": "navigate", "lifecycle": "complete", "t": 310},
    )
    result = performance_perspective(log)
    assert result.tables["waiting"].empty and result.summary["slowest_transition"] is None
    robot = result.tables["robots"].iloc[0]
    assert (robot["waiting"], robot["unsplit"]) == (0.0, 300.0)


@pytest.fixture
def paths(events):
    """Nine cases: r1 does a, b, c (six cases) or a, c (three); r2 does x in the first four."""
    rows = []
    for case in range(9):
        t = 0
        for activity in ("a", "b", "c") if case % 3 else ("a", "c"):
            rows += [(case, "r1", activity, "start", t), (case, "r1", activity, "complete", t + 5)]
            t += 5 + case
        if case < 4:
            rows += [(case, "r2", "x", "start", 1), (case, "r2", "x", "complete", 2)]
    return events(
        *[
            {"case": str(c), "robot": r, "activity": a, "lifecycle": lc, "t": t}
            for c, r, a, lc, t in rows
        ]
    )


def test_variants_per_case_and_per_robot_equal_pm4py(paths):
    starts = paths[paths["lifecycle:transition"] == "start"]
    starts = starts.sort_values(["case:concept:name", "time:timestamp"], kind="stable")
    expected = pm4py.get_variants(starts)  # pm4py's own variants of the start events
    result = performance_perspective(paths)
    variants = result.tables["variants"]
    assert dict(
        zip(variants["variant"].str.split(" -> ").map(tuple), variants["cases"], strict=True)
    ) == {variant: count for variant, count in expected.items()}
    per_robot = starts.assign(**{"case:concept:name": starts["case:concept:name"] + starts[ROBOT]})
    per_robot = per_robot.sort_values(["case:concept:name", "time:timestamp"], kind="stable")
    robot_variants = result.tables["robot_variants"]
    assert sorted(robot_variants["cases"]) == sorted(pm4py.get_variants(per_robot).values())
    ordered = paths.sort_values(["case:concept:name", "time:timestamp"], kind="stable")
    durations = pm4py.get_all_case_durations(ordered)  # first to last event of each case
    assert sorted(result.tables["cases"]["duration"]) == pytest.approx(sorted(durations))
    assert result.summary["variants"] == len(expected)


def test_activity_durations_count_interrupted_instances_by_hand():
    """Two instances of a by r1, one interrupted (XES' ate_abort); b's robot is missing, so
    its group has durations but no interrupted count, as a group-by that drops it gives."""
    from robotale.enhancement.performance import activity_durations

    instances = pd.DataFrame(
        {
            "concept:name": pd.array(["a", "b", "a", "c"], dtype="string"),
            ROBOT: pd.array(["r1", None, "r1", "r2"], dtype="string"),
            "duration": [1.0, 2.0, 3.0, 4.0],
            "lifecycle:transition": pd.array(
                ["complete", "ate_abort", "ate_abort", "Complete"], dtype="string"
            ),
        }
    )
    table = activity_durations(instances).set_index(["activity", "robot"])
    assert table.loc[("a", "r1"), ["count", "total", "interrupted"]].tolist() == [2, 4.0, 1]
    assert table.loc[("c", "r2"), "interrupted"] == 0
    assert pd.isna(table.loc[("b", pd.NA), "interrupted"]) and table.loc[("b", pd.NA), "count"] == 1
    whole = activity_durations(instances.dropna())
    assert whole["interrupted"].dtype == "int64" and whole["interrupted"].tolist() == [1, 0]
