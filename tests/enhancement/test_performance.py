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
