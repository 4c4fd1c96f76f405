"""Battery per robot and run, and robots at the same place at the same moment, on small logs
counted by hand."""

from __future__ import annotations

import pandas as pd
import pytest

from robotale.enhancement.battery import battery_perspective
from robotale.enhancement.encounters import encounters, positions
from robotale.enhancement.findings import find


def _row(case, robot, activity, lifecycle, t, **more):
    return {"case": case, "robot": robot, "activity": activity, "lifecycle": lifecycle, "t": t}


@pytest.fixture
def two_robots(events):
    """Two runs an hour apart. Per run the drone flies (0-100 s) from 90 % to 53 % (37
    points); the ugv works (0-40 s) from 80 % to 76 %, waits and charges to 86 % (40-60 s,
    +10) and works again (60-100 s) down to 80 % (6 points).

    By hand: used per run, each robot its own: drone 37, ugv 4 + 6 = 10 (never 47, a sum over
    robots); charged while waiting: ugv 10; used while waiting: 0, never negative."""
    rows = []
    for case, start in (("1", 0), ("2", 3600)):
        rows += [
            _row(case, "drone", "fly", "start", start) | {"battery": 90.0},
            _row(case, "drone", "fly", "complete", start + 100) | {"battery": 53.0},
            _row(case, "ugv", "work", "start", start) | {"battery": 80.0},
            _row(case, "ugv", "work", "complete", start + 40) | {"battery": 76.0},
            _row(case, "ugv", "work", "start", start + 60) | {"battery": 86.0},
            _row(case, "ugv", "work", "complete", start + 100) | {"battery": 80.0},
        ]
    return events(*rows)


def test_battery_per_robot_and_run_never_summed_never_negative(two_robots):
    result = battery_perspective(two_robots)
    assert result.summary["used_per_run"] == {"drone": 37.0, "ugv": 10.0}
    assert result.summary["used_while_waiting"] == {"ugv": 0.0}
    table = result.tables["consumption"].set_index(["activity", "robot"])
    assert table.loc[("(waiting)", "ugv"), "charged"] == 20.0  # 10 points in each run
    assert (table["used"] >= 0).all()
    energy = result.tables["energy"].set_index(["case", "robot"])
    assert energy["used"].to_dict() == {
        ("1", "drone"): 37.0,
        ("1", "ugv"): 10.0,
        ("2", "drone"): 37.0,
        ("2", "ugv"): 10.0,
    }
    # what the figures cover: each robot's first event to its last (0-100 s of each run)
    span = (energy["observed_to"] - energy["observed_from"]).dt.total_seconds()
    assert span.tolist() == [100.0] * 4
    assert energy["observed_from"].min() == two_robots["time:timestamp"].min()
    answer = find(two_robots).answer("battery")
    assert answer.sentences[0] == (
        "Battery used per run from each robot's first event to its last, each robot its own "
        "(mean): drone 37.0%, ugv 10.0%; "
        "the activity that used most: fly."
    )


def test_the_levels_chart_breaks_between_runs(two_robots):
    """Each robot's line has one gap, between its runs, and no point joins run 1 to run 2."""
    figure = battery_perspective(two_robots).figure
    lines = {trace.name: trace for trace in figure.data if trace.mode == "lines"}
    assert set(lines) == {"drone", "ugv"}
    for name, trace in lines.items():
        ys = list(trace.y)
        gap = ys.index(None)
        assert ys.count(None) == 1 and not trace.connectgaps
        xs = list(trace.x)
        first, second = pd.Timestamp(xs[gap - 1]), pd.Timestamp(xs[gap + 1])
        assert (second - first).total_seconds() == 3600 - 100, name


@pytest.fixture
def drone_over_ugv(events):
    """A drone flying 5-32 m above a ground robot that drives under it (same x, y), and a
    second ground robot that passes the first one's spot 1.5 m away, at the same moment
    (10 s), and again an hour later in run 2, when the first is elsewhere.

    By hand (2 m, 1 s): the drone meets no one (5 m at the closest); ugv_1 and ugv_2 meet once,
    in run 1 at 10 s, 1.5 m apart; in run 2 their regions overlap (the same spot, an hour
    apart) but they never meet."""
    rows = []
    for t in range(0, 21, 2):
        z = 5.0 + 27.0 * t / 20
        rows.append(_row("1", "uav_1", "fly", "none", t) | {"x": float(t), "y": 0.0, "z": z})
        rows.append(_row("1", "ugv_1", "drive", "none", t) | {"x": float(t), "y": 0.0, "z": 0.0})
    rows.append(_row("1", "ugv_2", "pass", "none", 10) | {"x": 10.0, "y": 1.5, "z": 0.0})
    rows.append(_row("1", "ugv_2", "pass", "none", 30) | {"x": 40.0, "y": 1.5, "z": 0.0})
    rows.append(_row("2", "ugv_1", "drive", "none", 100) | {"x": 0.0, "y": 0.0, "z": 0.0})
    rows.append(_row("2", "ugv_1", "drive", "none", 110) | {"x": 10.0, "y": 0.0, "z": 0.0})
    rows.append(_row("2", "ugv_2", "pass", "none", 3700) | {"x": 5.0, "y": 0.0, "z": 0.0})
    rows.append(_row("2", "ugv_2", "pass", "none", 3710) | {"x": 6.0, "y": 0.0, "z": 0.0})
    return events(*rows)


def test_same_place_same_moment_in_3d(drone_over_ugv):
    met = encounters(positions(drone_over_ugv))
    assert met[["robot", "other", "case:concept:name"]].values.tolist() == [["ugv_1", "ugv_2", "1"]]
    assert met["closest"].tolist() == [1.5]
    answer = find(drone_over_ugv).answer("robots")
    assert (
        "ugv_1 and ugv_2 were at the same place at the same moment (within 2 m and 1 s, in 3D) "
        "1 time in 1 run; the first in run 1 at 2024-01-01 10:00:10, at x 10.0, y 0.0, z 0.0 "
        "(1.5 m apart)."
    ) in answer.sentences
    assert not any("uav_1 and" in s for s in answer.sentences[-2:])
    # regions: run 1 ugv_1 (x 0-20) and ugv_2 (x 10-40, y 1.5) do not overlap on y; run 2
    # they share x 5-6, y 0, z 0 an hour apart; the drone's z 5-32 is above both
    assert [(o["case"], o["robots"]) for o in answer.facts["overlaps"]] == [
        ("2", ["ugv_1", "ugv_2"])
    ]
    assert answer.sentences[-1] == (
        "Regions (x, y and z, per run) overlap: ugv_1 and ugv_2 in 1 of 2 runs, "
        "not necessarily at the same time."
    )
