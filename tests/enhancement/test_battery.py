import pytest

from robotale.enhancement import battery_perspective, low_battery_events
from robotale.eventlog.schema import ACTIVITY, LIFECYCLE


@pytest.fixture
def drained(events):
    """A drone whose battery falls below 20% during its second survey, then returns home."""
    rows = [
        ("survey", "start", 0, 100.0),
        ("survey", "complete", 60, 70.0),
        ("survey", "start", 60, 70.0),
        ("survey", "complete", 120, 19.0),
        ("return_to_base", "start", 125, 18.0),
        ("return_to_base", "complete", 185, 10.0),
        ("land", "start", 185, 10.0),
        ("land", "complete", 195, 9.0),
    ]
    return events(
        *[
            {"case": "1", "robot": "drone", "activity": a, "lifecycle": lc, "t": t, "battery": b}
            for a, lc, t, b in rows
        ]
    )


def test_falling_below_the_threshold_and_what_followed(drained):
    lows = battery_perspective(drained, threshold=20).tables["low_battery"]
    assert len(lows) == 1
    low = lows.iloc[0]
    assert low["battery"] == 19.0 and low["time"] == drained["time:timestamp"].iloc[3]
    assert low["then"] == "return_to_base -> land"
    assert low["until_end"] == 75.0


def test_consumption_per_activity_by_hand(drained):
    table = battery_perspective(drained).tables["consumption"].set_index("activity")
    assert table.loc["survey", "used"] == (100 - 70) + (70 - 19)
    assert table.loc["survey", "used_per_instance"] == pytest.approx(81 / 2)
    assert table.loc["return_to_base", "used_per_minute"] == pytest.approx(8.0)
    one = battery_perspective(drained, activity="land").tables["consumption"]
    assert list(one["activity"]) == ["land"] and one["used"].iloc[0] == 1.0


def test_levels_over_time_per_robot(drained):
    result = battery_perspective(drained)
    line = result.figure.data[0]
    assert line.name == "drone" and list(line.y) == list(drained["battery"])
    assert result.summary["robots"] == ["drone"]


def test_thesis_log_has_tagged_low_battery_events(thesis_log):
    # no battery column, but the robots tag low_battery (thesis 7.2.2)
    lows = low_battery_events(thesis_log)
    starts = (thesis_log[ACTIVITY] == "low_battery") & (thesis_log[LIFECYCLE] == "start")
    assert len(lows) == starts.sum() == 7
    result = battery_perspective(thesis_log)
    drone = result.tables["low_battery"].query("robot == 'drone'")
    assert all(then.startswith("move -> land") for then in drone["then"])
    assert result.tables["levels"].empty


def test_a_log_without_battery_data_says_so(events):
    log = events({"case": "1", "robot": "a", "activity": "go", "lifecycle": "start", "t": 0})
    result = battery_perspective(log)
    assert not result.has_data and "no battery levels" in result.message
    assert battery_perspective(log, low_activity=None).message == result.message


def test_drill_down_to_a_robot_without_data(drained):
    result = battery_perspective(drained, robot="tractor_9")
    assert not result.has_data and "robot tractor_9" in result.message
