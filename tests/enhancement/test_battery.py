import pytest

from robotale.enhancement import battery_perspective, low_battery_events
from robotale.eventlog.readers import read_log
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


@pytest.fixture
def idle_drain(events):
    """Two missions of a rover: its tag events carry no level, samples (inprogress rows) do.
    It drains 1 %/min while idle between drive and dig and much faster while working."""
    rows = []
    for case, level in (("1", 90.0), ("2", 80.0)):
        tags = [("drive", "start", 0), ("drive", "complete", 60), ("dig", "start", 660)]
        tags += [("dig", "complete", 720)]
        samples = [(0, level), (60, level - 10), (660, level - 20), (720, level - 35)]
        rows += [(case, a, lc, t, None, None) for a, lc, t in tags]
        rows += [
            (case, "drive" if t <= 60 else "dig", "none", t, b, "inprogress") for t, b in samples
        ]
    return events(
        *[
            {"case": c, "robot": "rover", "activity": a, "lifecycle": lc, "t": t, "battery": b,
             "lifecycle:state": state}
            for c, a, lc, t, b, state in rows
        ]
    )  # fmt: skip


def test_battery_use_per_activity_counts_working_time_only(idle_drain):
    result = battery_perspective(idle_drain)
    table = result.tables["consumption"].set_index("activity")
    samples = idle_drain.dropna(subset=["battery"]).set_index(
        ["case:concept:name", "time:timestamp"]
    )
    level = samples["battery"].droplevel(1).groupby(level=0).agg(list)  # [start, 60, 660, 720]
    drive = sum(levels[0] - levels[1] for levels in level)
    dig = sum(levels[2] - levels[3] for levels in level)
    idle = sum(levels[1] - levels[2] for levels in level)
    assert table.loc["drive", "used"] == drive == 20
    assert table.loc["dig", "used"] == dig == 30  # not the 10 points lost while waiting
    assert table.loc["(waiting)", "used"] == idle and table.loc["(waiting)", "seconds"] == 1200
    assert table.loc["dig", "used_per_minute"] == pytest.approx(dig / 2)
    assert table.loc["dig", "start_level_mean"] == pytest.approx((70 + 60) / 2)
    assert result.summary["most_used_by"] == "dig"


def test_energy_per_case_by_hand(idle_drain, drained):
    energy = battery_perspective(idle_drain).tables["energy"].set_index("case")
    levels = idle_drain.dropna(subset=["battery"]).groupby("case:concept:name")["battery"]
    assert energy["used"].to_dict() == (levels.first() - levels.last()).to_dict()
    # per robot: the rover used 35 points in each of its two runs
    assert battery_perspective(idle_drain).summary["used_per_run"] == {"rover": 35.0}
    # the drone's battery only falls: used = first - last level, charged nothing
    drone = battery_perspective(drained).tables["energy"].iloc[0]
    assert drone["used"] == drained["battery"].iloc[0] - drained["battery"].iloc[-1]
    assert drone["charged"] == 0


def test_a_battery_column_of_zeros_is_no_battery_data(events):
    log = events(
        {"case": "1", "robot": "a", "activity": "go", "lifecycle": "start", "t": 0, "battery": 0},
        {
            "case": "1",
            "robot": "a",
            "activity": "go",
            "lifecycle": "complete",
            "t": 5,
            "battery": 0,
        },
    )
    result = battery_perspective(log)
    assert not result.has_data and result.message.count(".") == 1
    assert "no battery levels" in result.message


def test_low_battery_tags_without_levels_say_so(thesis_log):
    summary = battery_perspective(thesis_log).summary
    assert summary["battery_levels"] == "the log has no battery levels"
    assert "energy_used" not in summary


def test_what_followed_every_low_moment_of_the_thesis_days(thesis_csv):
    """Per low-battery moment of the thesis' five days (one run each): the next three
    activities its robot started in that run and the seconds to its last completion there,
    counted from the events one moment at a time."""
    log = read_log(thesis_csv, case_gap="1h")
    lows = battery_perspective(log).tables["low_battery"]
    assert lows["case"].nunique() > 1 and lows["robot"].nunique() > 1
    for low in lows.to_dict("records"):
        mine = log[(log["case:concept:name"] == low["case"]) & (log["robot"] == low["robot"])]
        starts = mine[(mine[LIFECYCLE] == "start") & (mine["time:timestamp"] > low["time"])]
        then = " -> ".join(starts.sort_values("time:timestamp", kind="stable")[ACTIVITY][:3])
        last = mine.loc[mine[LIFECYCLE] == "complete", "time:timestamp"].max()
        assert low["then"] == then
        assert low["until_end"] == pytest.approx((last - low["time"]).total_seconds())


def test_a_low_moment_after_its_robots_last_activity_is_followed_by_nothing(events):
    rows = [
        ("drone", "survey", "start", 0),
        ("drone", "survey", "complete", 50),
        ("rover", "dig", "start", 55),
        ("drone", "low_battery", "none", 60),
        ("rover", "dig", "complete", 90),
    ]
    log = events(
        *[{"case": "1", "robot": r, "activity": a, "lifecycle": lc, "t": t} for r, a, lc, t in rows]
    )
    [low] = battery_perspective(log).tables["low_battery"].to_dict("records")
    # the rover's dig, later, is another robot's work; the drone's last completion is the
    # low_battery event itself, at 60 s
    assert low["robot"] == "drone" and low["then"] == "" and low["until_end"] == 0.0
