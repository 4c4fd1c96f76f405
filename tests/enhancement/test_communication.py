import pandas as pd
import pytest

from robotale.enhancement import communication_perspective
from robotale.eventlog.schema import ACTIVITY, LIFECYCLE, ROBOT, TIMESTAMP


def by_hand(log: pd.DataFrame) -> pd.DataFrame:
    """Per message type, straight from the thesis' convention: '!' sends, '?' receives."""
    rows = []
    for _, events in log.dropna(subset=["msg_id"]).groupby("msg_id"):
        sends = events[events[ACTIVITY].str.endswith("!")]
        receives = events[events[ACTIVITY].str.endswith("?")]
        rows.append(
            {
                "type": sends[ACTIVITY].iloc[0],
                "received": not receives.empty,
                "attempts": (sends[LIFECYCLE] == "start").sum(),
                "latency": (receives[TIMESTAMP].min() - sends[TIMESTAMP].min()).total_seconds()
                if not receives.empty
                else None,
            }
        )
    messages = pd.DataFrame(rows)
    return messages.groupby("type").agg(
        sent=("type", "size"),
        received=("received", "sum"),
        resends=("attempts", lambda a: (a - 1).sum()),
        latency_mean=("latency", "mean"),
    )


def test_thesis_message_counts_equal_a_count_by_hand(thesis_log):
    expected = by_hand(thesis_log)
    table = communication_perspective(thesis_log).table.set_index("message_type")

    assert sorted(table.index) == ["closest_tractor!", "tractor_position!", "weed_position!"]
    for name, row in expected.iterrows():
        assert table.loc[name, "sent"] == row["sent"]
        assert table.loc[name, "received"] == row["received"]
        assert table.loc[name, "lost"] == row["sent"] - row["received"]
        assert table.loc[name, "resends"] == row["resends"]
        assert table.loc[name, "latency_mean"] == pytest.approx(row["latency_mean"])
    # as in the thesis, only weed_position! messages get lost
    assert table.loc["weed_position!", "lost"] > 0
    assert table.loc[["closest_tractor!", "tractor_position!"], "lost"].sum() == 0


def test_drill_down_to_a_receive_activity_and_a_robot(thesis_log):
    weed = communication_perspective(thesis_log, activity="weed_position?")
    assert list(weed.table["message_type"]) == ["weed_position!"]
    tractor = communication_perspective(thesis_log, robot="tractor_1")
    involved = thesis_log.loc[thesis_log[ROBOT] == "tractor_1", "msg_id"].dropna().nunique()
    assert tractor.summary["messages"] == involved
    explore = communication_perspective(thesis_log, activity="explore")
    assert not explore.has_data and "activity explore" in explore.message


def test_roles_from_msg_role_and_instant_sends(events):
    log = events(
        # m1: sent twice without lifecycle, received by two robots
        {
            "case": "1",
            "robot": "a",
            "activity": "report",
            "msg_id": "m1",
            "msg_role": "send",
            "t": 0,
        },
        {
            "case": "1",
            "robot": "a",
            "activity": "report",
            "msg_id": "m1",
            "msg_role": "send",
            "t": 5,
        },
        {
            "case": "1",
            "robot": "b",
            "activity": "hear",
            "msg_id": "m1",
            "msg_role": "receive",
            "t": 6,
        },
        {
            "case": "1",
            "robot": "c",
            "activity": "hear",
            "msg_id": "m1",
            "msg_role": "receive",
            "t": 7,
        },
        # m2: sent, lost
        {
            "case": "1",
            "robot": "a",
            "activity": "report",
            "msg_id": "m2",
            "msg_role": "send",
            "t": 8,
        },
        # m3: only its receive was recorded
        {"case": "1", "robot": "b", "activity": "ping?", "msg_id": "m3", "t": 9},
    )
    messages = communication_perspective(log).tables["messages"].set_index("msg_id")
    assert messages.loc["m1", "attempts"] == 2 and messages.loc["m1", "resends"] == 1
    assert messages.loc["m1", "receivers"] == 2 and messages.loc["m1", "latency"] == 6.0
    assert bool(messages.loc["m2", "lost"]) and not bool(messages.loc["m2", "received"])
    assert messages.loc["m3", "message_type"] == "ping!"
    assert not bool(messages.loc["m3", "sent"]) and not bool(messages.loc["m3", "lost"])


def test_same_message_ids_in_two_cases_are_two_messages(events):
    log = events(
        {"case": "1", "robot": "a", "activity": "x!", "msg_id": "m1", "t": 0},
        {"case": "1", "robot": "b", "activity": "x?", "msg_id": "m1", "t": 1},
        {"case": "2", "robot": "a", "activity": "x!", "msg_id": "m1", "t": 0},
    )
    result = communication_perspective(log)
    assert (result.summary["sent"], result.summary["received"], result.summary["lost"]) == (2, 1, 1)


def test_a_log_without_messages_says_so(events):
    log = events({"case": "1", "robot": "a", "activity": "go", "t": 0})
    assert "no messages" in communication_perspective(log).message
    with_column = log.assign(msg_id=pd.Series([None], dtype="string"))
    assert not communication_perspective(with_column).has_data


def test_figure_shows_received_and_lost_per_type(thesis_log):
    figure = communication_perspective(thesis_log).figure
    lost = next(trace for trace in figure.data if trace.name == "lost")
    assert dict(zip(lost.x, lost.y, strict=True))["weed_position!"] > 0
