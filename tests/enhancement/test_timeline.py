"""One run's timeline (a lane per robot, its activity instances as bars, messages as arrows
from sender to receiver with lost ones marked, battery as a line) against the mission's truth
(``tests/mission_findings.py``), counted here with pandas, in each convention."""

from __future__ import annotations

import mission_findings as mission
import pandas as pd
import pytest

from robotale.enhancement.timeline import case_timeline, run_list
from robotale.errors import InputError
from robotale.eventlog.readers import read_log

TRUTH = mission.injected_truth()
LOST_RUN = sorted(mission.LOST_RUNS)[0]


@pytest.fixture(scope="module", params=list(mission.WRITERS))
def timeline(request, tmp_path_factory):
    path = mission.write_injected(request.param, tmp_path_factory.mktemp("t") / request.param)
    return request.param, case_timeline(read_log(path), LOST_RUN)


def _rows(frame: pd.DataFrame, columns: list[str]) -> list[tuple]:
    return sorted(frame[columns].itertuples(index=False, name=None), key=str)


def test_a_bar_per_activity_instance_in_a_lane_per_robot(timeline):
    _, found = timeline
    table = TRUTH.instance_table()
    mine = table[table["case"] == LOST_RUN]
    assert found.robots == sorted(mine["robot"].unique())
    columns = ["robot", "activity", "start", "end"]
    assert _rows(found.bars, columns) == _rows(mine, columns)
    assert found.bars["seconds"].sum() == pytest.approx(mine["seconds"].sum())


def test_messages_from_sender_to_receiver_and_the_lost_one(timeline):
    convention, found = timeline
    truth = pd.DataFrame([vars(m) for m in TRUTH.messages])
    mine = truth[truth["case"] == LOST_RUN]
    mine = mine.assign(lost=mine["received"].isna())
    if convention != "robot_id.csv":  # only msg_receiver names a lost message's receiver
        mine.loc[mine["lost"], "receiver"] = "unknown"
    columns = ["msg_id", "sender", "receiver", "sent", "lost"]
    assert _rows(found.messages, columns) == _rows(mine, columns)
    assert found.lost == mine["lost"].sum() == 1
    figure = found.to_dict()["figure"]
    arrows = next(t for t in figure["data"] if t["name"] == "message")
    delivered = mine[~mine["lost"]].sort_values("sent")
    # each delivered message is one segment: from the sender's lane to the receiver's
    assert arrows["y"] == [
        lane for m in delivered.itertuples() for lane in (m.sender, m.receiver, None)
    ]
    crosses = next(t for t in figure["data"] if t["name"] == "lost message")
    assert crosses["y"] == mine.loc[mine["lost"], "sender"].tolist()
    assert crosses["text"] == mine.loc[mine["lost"], "msg_id"].tolist()


def test_battery_as_a_line_per_robot(timeline):
    convention, found = timeline
    if convention == "robot_id.csv":  # its levels are on the events, not in samples
        return
    samples = pd.DataFrame([vars(s) for s in TRUTH.samples])
    mine = samples[samples["case"] == LOST_RUN].rename(columns={"battery": "level"})
    assert _rows(found.battery, ["robot", "time", "level"]) == _rows(
        mine, ["robot", "time", "level"]
    )
    figure = found.to_dict()["figure"]
    lines = sorted(t["name"] for t in figure["data"] if t["name"].startswith("battery "))
    assert lines == [f"battery {robot}" for robot in sorted(mine["robot"].unique())]


def test_runs_in_start_order_and_an_unknown_run(tmp_path):
    log = read_log(mission.write_injected("robotale.csv", tmp_path / "m.csv"))
    runs = run_list(log)
    assert runs["case"].tolist() == sorted(mission.STARTS, key=mission.STARTS.get)
    with pytest.raises(InputError, match="the log has no run 'run99'; its runs include run01"):
        case_timeline(log, "run99")
