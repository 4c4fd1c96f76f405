"""Lost, unobserved, resent and delayed messages on small logs whose answers are counted by
hand in each test's docstring."""

from __future__ import annotations

import pandas as pd
import pytest

from robotale.enhancement import communication_perspective
from robotale.enhancement.findings import find


def message(events, case, msg, activity, t, robot, **more):
    return {"case": case, "robot": robot, "activity": activity, "msg_id": msg, "t": t, **more}


@pytest.fixture
def scout_and_worker(events):
    """The scout sends targets to the worker, whose skill consumes them (no receive tag), and
    the worker reports each done (consumed by the scout's skill: no receive tag either).

    - m_2 target at 0, the worker's m_3 done at 10 (the answer), m_4 next target at 11:
      m_4 is news, not a resend of m_2; the worker's m_4d done at 15 answers m_4;
    - m_5 target at 20, no answer, m_6 target again at 30: m_6 repeats m_5;
    - status! is receive-tagged: m_7 at 40 received at 41, m_8 at 50 never received (lost);
    - base -> worker task! m_9 at 55, received at 56 (task! is receive-tagged); task! m_10 at
      60 gets no answer, and base sends task_retry! m_11 at 70 with the payload "task resent
      after missing ack", received at 71: a resend under another type repeating m_10.

    By hand: 11 messages; received m_7, m_9, m_11 (3); lost m_8 and m_10 (2); not observed as
    received m_2, m_3, m_4, m_4d, m_5, m_6 (6: target! and target_done! have no receive tags);
    resends under a new id: m_6 (repeats m_5) and m_11 (repeats m_10)."""
    rows = [
        message(events, "1", "m_2", "target!", 0, "scout"),
        message(events, "1", "m_3", "target_done!", 10, "worker"),
        message(events, "1", "m_4", "target!", 11, "scout"),
        message(events, "1", "m_4d", "target_done!", 15, "worker"),
        message(events, "1", "m_5", "target!", 20, "scout"),
        message(events, "1", "m_6", "target!", 30, "scout"),
        message(events, "1", "m_7", "status!", 40, "worker"),
        message(events, "1", "m_7", "status?", 41, "scout"),
        message(events, "1", "m_8", "status!", 50, "worker"),
        message(events, "1", "m_9", "task!", 55, "base", msg_receiver="worker"),
        message(events, "1", "m_9", "task?", 56, "worker"),
        message(events, "1", "m_10", "task!", 60, "base", msg_receiver="worker"),
        message(
            events,
            "1",
            "m_11",
            "task_retry!",
            70,
            "base",
            msg_receiver="worker",
            msg_payload="task resent after missing ack",
        ),
        message(events, "1", "m_11", "task_retry?", 71, "worker"),
    ]
    return events(*rows)


def test_no_receive_tags_is_not_lost(scout_and_worker):
    result = communication_perspective(scout_and_worker)
    summary = result.summary
    assert (summary["messages"], summary["received"]) == (11, 3)
    assert summary["lost"] == 2 and summary["unobserved"] == 6
    assert summary["untagged_types"] == ["target!", "target_done!"]
    messages = result.tables["messages"].set_index("msg_id")
    assert sorted(messages.index[messages["lost"]]) == ["m_10", "m_8"]
    assert sorted(messages.index[messages["unobserved"]]) == [
        "m_2",
        "m_3",
        "m_4",
        "m_4d",
        "m_5",
        "m_6",
    ]
    types = result.tables["message_types"].set_index("message_type")
    assert not types.loc["target!", "receive_tagged"] and pd.isna(types.loc["target!", "loss_rate"])
    assert types.loc["status!", "loss_rate"] == 0.5


def test_findings_say_not_observed_and_which_types_lack_receive_tags(scout_and_worker):
    answer = find(scout_and_worker).answer("messages")
    assert answer.sentences[0].startswith(
        "11 messages sent: 3 received, 2 lost, 6 not observed as received, 0 delayed, 2 resends"
    )
    assert answer.sentences[1] == (
        "The log tags no receive of target!, target_done!: whether those messages arrived is "
        "unknown, so none of them is called lost."
    )


def test_resends_are_what_a_resend_is(scout_and_worker):
    messages = communication_perspective(scout_and_worker).tables["messages"]
    repeats = messages.dropna(subset=["repeats"]).set_index("msg_id")["repeats"].to_dict()
    assert repeats == {"m_6": "m_5", "m_11": "m_10"}
    named = messages.set_index("msg_id")
    assert pd.isna(named.loc["m_4", "repeats"])  # the next target after the worker's answer
    assert named.loc["m_10", "resent_as"] == "m_11"
    assert bool(named.loc["m_10", "recovered"])  # lost, and its resend got through


def test_a_reply_from_someone_else_is_no_answer(events):
    """r1 asks base (m1, no receive tags), r2 (not base) then messages r1, r1 asks again (m3):
    base never answered, so m3 repeats m1."""
    log = events(
        message(events, "1", "m1", "ask!", 0, "r1", msg_receiver="base"),
        message(events, "1", "m2", "hello!", 5, "r2", msg_receiver="r1"),
        message(events, "1", "m3", "ask!", 9, "r1", msg_receiver="base"),
    )
    named = communication_perspective(log).tables["messages"].set_index("msg_id")
    assert named.loc["m3", "repeats"] == "m1" and pd.isna(named.loc["m2", "repeats"])


def test_an_answer_lost_on_the_way_leaves_the_question_unanswered(events):
    """A coordinator asks a worker (ask!, payload the task), the worker answers (reply!):

    - m1 "task 0" at 0, received at 0.1; the reply m2 at 0.1 is lost (reply! is receive-tagged);
    - m3 "task 0" at 5, received at 5.1; the reply m4 at 5.1 arrives at 5.2;
    - m5 "task 1" at 5.2, received at 5.3; the reply m6 at 5.3 is lost;
    - m7 "task 2" at 10 (the coordinator gave task 1 up), received at 10.1; the reply m8 at
      10.1 is lost;
    - m9 "task 3" at 10.2, received at 10.25; the reply m10 at 10.25 arrives at 10.3.

    By hand: m3 repeats m1 (received, but its answer never came back); m5 follows an answer;
    m7 and m9 carry other tasks (ask!'s payloads name their task: "task 0" went twice); m10
    answers the question the worker heard after m8, it repeats nothing. One resend: m3."""
    ask = {"msg_receiver": "worker"}
    rows = []
    for msg, t, task, got, reply, back in (
        ("m1", 0, "task 0", 0.1, "m2", None),
        ("m3", 5, "task 0", 5.1, "m4", 5.2),
        ("m5", 5.2, "task 1", 5.3, "m6", None),
        ("m7", 10, "task 2", 10.1, "m8", None),
        ("m9", 10.2, "task 3", 10.25, "m10", 10.3),
    ):
        rows.append(message(events, "1", msg, "ask!", t, "coordinator", msg_payload=task, **ask))
        rows.append(message(events, "1", msg, "ask?", got, "worker"))
        rows.append(message(events, "1", reply, "reply!", got, "worker", msg_payload=task))
        if back is not None:
            rows.append(message(events, "1", reply, "reply?", back, "coordinator"))
    messages = communication_perspective(events(*rows)).tables["messages"]
    repeats = messages.dropna(subset=["repeats"]).set_index("msg_id")["repeats"].to_dict()
    assert repeats == {"m3": "m1"}
    named = messages.set_index("msg_id")
    assert sorted(named.index[named["lost"]]) == ["m2", "m6", "m8"]


def _latency_log(events, latencies: list[float]):
    rows = []
    for n, latency in enumerate(latencies):
        rows.append(message(events, "1", f"m{n}", "ping!", 10 * n, "a"))
        rows.append(message(events, "1", f"m{n}", "ping?", 10 * n + latency, "b"))
    return events(*rows)


def test_latencies_all_alike_have_no_delay(events):
    """Twenty latencies spread evenly from 0.10 to 0.29 s: one mode, nothing delayed (a 95th
    percentile rule would call one of them delayed)."""
    log = _latency_log(events, [0.10 + 0.01 * n for n in range(20)])
    result = communication_perspective(log)
    assert result.summary["delayed"] == 0
    assert "two-mode" in result.summary["delay_rule"]


def test_the_slow_mode_of_two_is_delayed(events):
    """Ten latencies of 0.1-0.2 s and six of 4-6 s (delays are common): the six are delayed;
    the channel's table says from 4 s on."""
    fast = [0.1, 0.12, 0.15, 0.2, 0.11, 0.13, 0.14, 0.1, 0.18, 0.16]
    slow = [4.0, 5.0, 6.0, 4.5, 5.5, 4.2]
    result = communication_perspective(_latency_log(events, fast + slow))
    assert result.summary["delayed"] == 6
    assert result.tables["channels"]["delayed_from"].tolist() == [4.0]


def test_an_explicit_threshold_and_the_rule_stated(events):
    """With a threshold of 0.15 s, 0.16, 0.18, 0.2 and the six slow ones are delayed (9)."""
    fast = [0.1, 0.12, 0.15, 0.2, 0.11, 0.13, 0.14, 0.1, 0.18, 0.16]
    slow = [4.0, 5.0, 6.0, 4.5, 5.5, 4.2]
    result = communication_perspective(_latency_log(events, fast + slow), delay_threshold=0.15)
    assert result.summary["delayed"] == 9
    assert result.summary["delay_rule"] == "a latency above 0.15 s (the threshold given)"
    answer = find(_latency_log(events, fast + slow), delay_threshold=0.15).answer("messages")
    assert "Delayed means a latency above 0.15 s (the threshold given)." in answer.sentences
