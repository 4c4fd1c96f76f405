"""A throw and the wait that always follows it mined as one step; a loop of steps that always
went round the same number of times written out. The truth: traces written by hand, with
the structure the driving model gives them (a coordinator that asks three times in vain,
then gets an answer for each of two tasks)."""

from __future__ import annotations

from robotale.discovery.answers import answered
from robotale.discovery.collaboration import discover_collaboration, mine
from robotale.discovery.layout import Leaf, Operator, Tau, leaves
from robotale.discovery.repeats import _rounds, loop_key, steps_loops, unrolled
from robotale.discovery.signal_starts import started_on_signals

ASKING = ["ping!", "no_answer", "count_try"]
ANSWERED = ["next_task", "ping!", "pong?"]
TRACE = ["check", "plan", *ASKING * 3, *ANSWERED * 2, "next_task", "all_done!"]
ROLES = {"ping!": "send", "pong?": "receive", "all_done!": "send"}


def _kinds(block) -> set[str]:
    if not isinstance(block, Operator):
        return set()
    return {block.kind}.union(*map(_kinds, block.children))


def test_each_ping_waits_for_its_answer_or_its_timeout():
    assert answered([TRACE], ROLES) == {"no_answer": "ping!", "pong?": "ping!"}
    assert "and" in _kinds(mine([TRACE]))  # the miner alone: pings beside the waits
    block = mine([TRACE], roles=ROLES)
    assert "and" not in _kinds(block)
    steps = leaves(block)
    assert {steps[i + 1] for i, step in enumerate(steps) if step == "ping!"} == {
        "no_answer",
        "pong?",
    }


def test_a_throw_repeated_or_ending_a_trace_is_no_pair():
    # weed_position! follows itself; all_done! ends the trace; nothing caught after tell!
    traces = [["weed_position!", "weed_position!", "look", "all_done!"], ["tell!", "look"]]
    roles = {**ROLES, "weed_position!": "send", "tell!": "send"}
    assert answered(traces, roles) == {}
    # a catch that also comes without the throw before it
    assert (
        answered([["ask!", "answer?"], ["answer?"]], {"ask!": "send", "answer?": "receive"}) == {}
    )


def test_a_loop_that_always_went_round_three_times_is_written_out():
    loops = steps_loops(mine([TRACE], roles=ROLES))
    counts = {
        loop_key(loop): _rounds(TRACE, leaves(loop.children[0]), leaves(loop.children[1]))
        for loop in loops
    }
    assert sorted(counts.values()) == [[3], [3]]
    loop = Operator("loop", [Operator("seq", [Leaf("a"), Leaf("b")]), Tau()])
    assert unrolled(loop, {loop_key(loop): 3}) == Operator("seq", [Leaf(x) for x in "ababab"])
    redo = Operator("loop", [Leaf("a"), Leaf("b")])
    assert unrolled(redo, {loop_key(redo): 2}) == Operator("seq", [Leaf(x) for x in "aba"])


def test_the_thesis_tractors_answer_does_not_always_follow_their_throw(thesis_log):
    """The thesis' tractors: ``move`` is logged between ``tractor_position!`` and the
    ``closest_tractor?`` that decides it in some instances (counted with pandas), so the
    catch is no pair of the throw and stays beside the work, as the miner alone draws it."""
    starts = thesis_log[
        thesis_log["robot"].astype(str).str.startswith("tractor")
        & (thesis_log["lifecycle:transition"] == "start")
    ].sort_values(["robot", "time:timestamp"], kind="stable")
    names = starts["concept:name"].astype(str)
    after = names.groupby(starts["robot"]).shift(-1)[names == "tractor_position!"]
    assert set(after) == {"closest_tractor?", "move"}
    tractor = started_on_signals(discover_collaboration(thesis_log), thesis_log).pool("Tractor")
    assert "and" in _kinds(tractor.block)
