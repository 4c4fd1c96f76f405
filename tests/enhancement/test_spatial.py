import pandas as pd
import pytest

from robotale.enhancement import Field, spatial_perspective
from robotale.errors import InputError
from robotale.eventlog.schema import ACTIVITY, ROBOT


def test_bounds_match_the_data(thesis_log):
    result = spatial_perspective(thesis_log)
    for axis in ("x", "y", "z"):
        assert result.summary["bounds"][axis] == [thesis_log[axis].min(), thesis_log[axis].max()]
    assert result.summary["positions"] == len(thesis_log)


def test_occupancy_per_activity_and_robot_by_hand(thesis_log):
    table = spatial_perspective(thesis_log).table.set_index(["activity", "robot"])
    explore = thesis_log[(thesis_log[ACTIVITY] == "explore") & (thesis_log[ROBOT] == "drone")]
    row = table.loc[("explore", "drone")]
    assert row["positions"] == len(explore)
    assert row["x_max"] == explore["x"].max() and row["y_min"] == explore["y"].min()
    assert row["z_mean"] == pytest.approx(explore["z"].mean())
    # tractors stay on the ground, the drone flies (thesis figure 7.8)
    assert table.loc[("cut_grass", "tractor_1"), "z_max"] == 0.0
    assert row["z_min"] > 1.0


def test_drill_down_to_one_class(thesis_log):
    result = spatial_perspective(thesis_log, activity="explore", robot="drone")
    assert list(result.table["activity"]) == ["explore"]
    drone_explore = (thesis_log[ACTIVITY] == "explore") & (thesis_log[ROBOT] == "drone")
    assert result.summary["positions"] == drone_explore.sum()
    assert sum(len(trace.x) for trace in result.figure.data) == drone_explore.sum()
    assert result.figure.data[0].type == "scatter3d"


def test_covered_fraction_follows_the_path(events):
    # along y = 0.5 from x = 0.5 to 3.5, then up x = 3.5 to y = 3.5: 4 + 3 of 16 cells,
    # then out of the field
    log = events(
        {"case": "1", "robot": "r", "activity": "go", "t": 0, "x": 0.5, "y": 0.5},
        {"case": "1", "robot": "r", "activity": "go", "t": 1, "x": 3.5, "y": 0.5},
        {"case": "1", "robot": "r", "activity": "go", "t": 2, "x": 3.5, "y": 3.5},
        {"case": "1", "robot": "r", "activity": "go", "t": 3, "x": 6.0, "y": 3.5},
    )
    result = spatial_perspective(log, field=Field(0, 4, 0, 4))
    assert result.summary["field"]["covered_fraction"] == 7 / 16
    assert result.summary["field"]["cells"] == 16
    coverage = result.tables["coverage"].iloc[0]
    assert (coverage["positions_inside"], coverage["positions_outside"]) == (3, 1)
    assert "z" not in log.columns  # a log with x and y only is enough


def test_thesis_drone_explores_part_of_the_field(thesis_log):
    field = Field.parse("0,10,0,10")
    result = spatial_perspective(thesis_log, activity="explore", robot="drone", field=field)
    # the drone never reaches the lower half of the 10 x 10 field (thesis 7.2.2)
    assert thesis_log.loc[thesis_log[ACTIVITY] == "explore", "y"].min() > 4.5
    assert 0 < result.summary["field"]["covered_fraction"] <= 0.55


def test_without_positions_the_perspective_says_so(events):
    log = events({"case": "1", "activity": "a", "t": 0})
    result = spatial_perspective(log)
    assert not result.has_data and "no positions" in result.message
    unplaced = log.assign(x=float("nan"), y=float("nan"))
    assert "has a position" in spatial_perspective(unplaced).message
    assert result.to_dict()["tables"] == {}


def test_bad_fields_are_refused():
    with pytest.raises(InputError, match="not x_min,x_max,y_min,y_max"):
        Field.parse("0,10,zero,10")
    with pytest.raises(InputError, match="is empty"):
        Field.parse("10,0,0,10")
    assert Field.parse("0,10,0,5,0.5").shape == (20, 10)


def test_positions_as_json(thesis_log):
    data = spatial_perspective(thesis_log.head(50)).to_dict()
    assert data["figures"]["scatter"]["data"][0]["type"] == "scatter3d"
    assert isinstance(pd.DataFrame(data["tables"]["occupancy"]), pd.DataFrame)
