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


def new_id_resends(log: pd.DataFrame) -> pd.Series:
    """Per message type: messages the sender sent again under another id of the same type
    while they had no answer (no receive, and no message of another robot since), with the
    same payload where the type's payloads name their content (one of them was sent twice: a
    weed's position), counted with a plain loop over the thesis' sends (every sender there
    is one robot)."""
    found: dict[str, int] = {}
    with_id = log.dropna(subset=["msg_id"])
    sends = with_id[with_id[ACTIVITY].str.endswith("!")]
    firsts = sends.groupby("msg_id").agg(
        type=(ACTIVITY, "first"),
        sender=(ROBOT, "first"),
        sent=(TIMESTAMP, "min"),
        payload=("msg_payload", "first"),
    )
    naming = {
        key: group["payload"].dropna().duplicated().any()
        for key, group in firsts.groupby(["sender", "type"])
    }
    receives = with_id[with_id[ACTIVITY].str.endswith("?")].groupby("msg_id")[TIMESTAMP].min()
    firsts["received"] = receives.reindex(firsts.index)
    ordered = list(firsts.sort_values("sent").itertuples())
    for i, after in enumerate(ordered):
        for this in reversed(ordered[:i]):
            if (this.sender, this.type) != (after.sender, after.type):
                continue
            answered = not pd.isna(this.received) and this.received <= after.sent
            replied = any(
                other.sender != this.sender and this.sent < other.sent < after.sent
                for other in ordered
            )
            news = naming[(this.sender, this.type)] and this.payload != after.payload
            if not answered and not replied and not news:
                found[after.type] = found.get(after.type, 0) + 1
            break
    return pd.Series(found, dtype=int)


def test_thesis_message_counts_equal_a_count_by_hand(thesis_log):
    expected = by_hand(thesis_log)
    table = communication_perspective(thesis_log).table.set_index("message_type")

    assert sorted(table.index) == ["closest_tractor!", "tractor_position!", "weed_position!"]
    for name, row in expected.iterrows():
        assert table.loc[name, "sent"] == row["sent"]
        assert table.loc[name, "received"] == row["received"]
        assert table.loc[name, "lost"] == row["sent"] - row["received"]
        # resends: by id reuse (the same id sent again) plus under a new id
        assert table.loc[name, "resends_same_id"] == row["resends"]
        new_ids = new_id_resends(thesis_log).get(name, 0)
        assert table.loc[name, "resends_new_id"] == new_ids
        assert table.loc[name, "resends"] == row["resends"] + new_ids
        assert table.loc[name, "latency_mean"] == pytest.approx(row["latency_mean"])
    # as in the thesis, only weed_position! messages get lost
    assert table.loc["weed_position!", "lost"] > 0
    assert table.loc[["closest_tractor!", "tractor_position!"], "lost"].sum() == 0
    # the drone resends lost weed positions under new ids (the same weed, a new message)
    assert table.loc["weed_position!", "resends_new_id"] > 0


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


@pytest.fixture
def recoveries(events):
    """Case 1: the base asks r1 to go (m1, sent twice under its id, received); r1 reports done
    under m2, no answer, so again under m3 (same payload, new id, received 40 s after sending);
    then status m4 under a different payload. Case 2: m2 reports once and is received. The
    columns msg_sender / msg_receiver name the channel; the robot column is the logger's."""

    def message(case, msg, activity, t, payload, sender, receiver):
        return {
            "case": case,
            "robot": "logger",
            "activity": activity,
            "msg_id": msg,
            "msg_payload": payload,
            "msg_sender": sender,
            "msg_receiver": receiver,
            "t": t,
        }

    return events(
        message("1", "m1", "go!", 0, "go", "base", "r1"),
        message("1", "m1", "go!", 5, "go", "base", "r1"),
        message("1", "m1", "go?", 6, "go", "base", "r1"),
        message("1", "m2", "done!", 10, "done", "r1", "base"),
        message("1", "m3", "done!", 30, "done", "r1", "base"),
        message("1", "m3", "done?", 70, "done", "r1", "base"),
        message("1", "m4", "done!", 80, "status", "r1", "base"),
        message("1", "m4", "done?", 81, "status", "r1", "base"),
        message("2", "m2", "done!", 0, "done", "r1", "base"),
        message("2", "m2", "done?", 1, "done", "r1", "base"),
    )


def test_resends_by_id_reuse_and_by_a_new_id(recoveries):
    result = communication_perspective(recoveries)
    messages = result.tables["messages"].set_index(["case", "msg_id"])
    assert messages.loc[("1", "m1"), "resends_same_id"] == 1  # go! sent at 0 and 5
    assert messages.loc[("1", "m2"), "resent_as"] == "m3"  # unanswered, new id
    # the resend is counted once, on the message that repeats, which names what it repeats
    assert messages.loc[("1", "m3"), "repeats"] == "m2"
    assert messages.loc[("1", "m3"), "resends"] == 1 and messages.loc[("1", "m2"), "resends"] == 0
    assert bool(messages.loc[("1", "m2"), "lost"]) and bool(messages.loc[("1", "m2"), "recovered"])
    # m3 was received (70 s) before m4 was sent (80 s): m4 is news, not a resend
    assert messages.loc[("1", "m4"), "resends"] == 0 and pd.isna(
        messages.loc[("1", "m4"), "repeats"]
    )
    sends = recoveries[recoveries["concept:name"].str.endswith("!")]
    attempts = sends.groupby(["case:concept:name", "msg_id"]).size()
    assert result.summary["resends_same_id"] == (attempts - 1).sum() == 1
    assert result.summary["resends_new_id"] == 1 and result.summary["resends"] == 2
    assert result.summary["messages"] == len(attempts) == 5


def test_channels_come_from_msg_sender_and_msg_receiver(recoveries):
    channels = communication_perspective(recoveries, delay_threshold=30).tables["channels"]
    table = channels.set_index(["sender", "receiver", "message_type"])
    expected = (
        recoveries.drop_duplicates(["case:concept:name", "msg_id"])
        .groupby(["msg_sender", "msg_receiver", "concept:name"])
        .size()
    )
    assert table["sent"].to_dict() == expected.to_dict()
    assert table.loc[("r1", "base", "done!"), "lost"] == 1
    # m3 took 40 s, above the 30 s threshold
    assert table.loc[("r1", "base", "done!"), "delayed"] == 1
    assert table.loc[("base", "r1", "go!"), "latency_max"] == 6.0


def test_a_lost_message_and_what_it_caused(events):
    """Three missions of a drone reporting to a tractor; in mission 1 the report is lost and
    the drone searches again before landing."""
    rows = []
    for case, lost in (("1", True), ("2", False), ("3", False)):
        rows += [
            ("drone", "report!", "start", 10, "m"),
            ("drone", "report!", "complete", 11, "m"),
        ]
        if not lost:
            rows += [
                ("tractor", "report?", "start", 12, "m"),
                ("tractor", "report?", "complete", 12, "m"),
            ]
            rows += [("drone", "land", "start", 20 + int(case), None)]
            rows += [("drone", "land", "complete", 30 + int(case), None)]
        else:
            rows += [
                ("drone", "search", "start", 15, None),
                ("drone", "search", "complete", 75, None),
            ]
            rows += [("drone", "land", "start", 80, None), ("drone", "land", "complete", 90, None)]
        rows = [(case, *row) if len(row) == 5 else row for row in rows]
    log = events(
        *[
            {"case": c, "robot": r, "activity": a, "lifecycle": lc, "t": t, "msg_id": m}
            for c, r, a, lc, t, m in rows
        ]
    )
    result = communication_perspective(log)
    lost = result.tables["lost"]
    assert len(lost) == 1 and lost.iloc[0]["case"] == "1"
    assert lost.iloc[0]["then"] == "search -> land"
    times = log.groupby("case:concept:name")["time:timestamp"]
    seconds = (times.max() - times.min()).dt.total_seconds()
    assert lost.iloc[0]["ended_later_by"] == seconds["1"] - seconds[["2", "3"]].median()
    assert lost.iloc[0]["until_end"] == 90 - 10
    assert lost.iloc[0]["receiver"] == "tractor"  # every other report went to the tractor
    assert result.summary["lost_cases_longer_by"] == seconds["1"] - seconds[["2", "3"]].mean()


def test_every_received_message_names_its_receivers_in_order(thesis_log):
    """A received message's receiver is the robots of its receive events, sorted and joined;
    counted here one message at a time."""
    messages = communication_perspective(thesis_log).tables["messages"]
    events = thesis_log.dropna(subset=["msg_id"])
    received = events[events[ACTIVITY].str.endswith("?")]
    expected = received.groupby("msg_id")[ROBOT].agg(lambda r: ", ".join(sorted(set(r))))
    got = messages[messages["received"]].set_index("msg_id")["receiver"]
    assert (got.str.contains(", ")).sum() > 0  # some messages reach several robots
    assert got.sort_index().to_dict() == expected.sort_index().to_dict()
