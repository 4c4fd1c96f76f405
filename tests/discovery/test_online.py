"""Online conformance: the tags the engine itself emits are all allowed by their pool's net,
and hand-made faults (a skipped activity, both branches of an exclusive choice, a join passed
before its branches end) are flagged at the very tag where the run left the model."""

from pathlib import Path

import pytest

from robotale.cli import main
from robotale.discovery.online import pool_replays
from robotale.fame_runtime.tags import Tag

MODELS = Path(__file__).resolve().parents[1] / "fame_runtime" / "models"


def flagged(model: str, steps: list[tuple[str, str]]) -> list[int]:
    """The positions of the tags the rover's replay does not allow."""
    replay = pool_replays(MODELS / model, ["rover"])["rover"]
    tags = [
        Tag(float(k), "rover", activity, lifecycle) for k, (activity, lifecycle) in enumerate(steps)
    ]
    return [k for k, tag in enumerate(tags) if not replay.allows(tag)]


def starts(*activities: str) -> list[tuple[str, str]]:
    return [(a, lifecycle) for a in activities for lifecycle in ("start", "complete")]


def test_the_engines_own_run_of_a_parallel_pool_is_allowed_tag_by_tag(capsys):
    assert main(["fame", "run", str(MODELS / "parallel.bpmn")]) == 0
    printed = [line.split("\t") for line in capsys.readouterr().out.splitlines() if "\t" in line]
    steps = [(row[2], row[3]) for row in printed]
    assert ("after_join", "start") in steps  # the run went through the whole pool
    assert flagged("parallel.bpmn", steps) == []


@pytest.mark.parametrize(
    ("model", "steps", "where"),
    [
        # Measure skipped: Carry On cannot start after Prepare
        ("sequence.bpmn", starts("prepare", "carry_on"), [2]),
        # an exclusive choice takes one branch: after Raise Alarm, Carry On is not allowed
        ("sequence.bpmn", starts("prepare", "measure", "raise_alarm", "carry_on"), [6]),
        ("sequence.bpmn", starts("prepare", "measure", "carry_on"), []),
        # the join waits for a and c: after_join right after b is not allowed
        ("parallel.bpmn", starts("b", "after_join", "c", "a"), [2]),
        # c follows b on its branch; the early c moved nothing, so the join still waits for a c
        ("parallel.bpmn", starts("c", "b", "a", "after_join"), [0, 6]),
        ("parallel.bpmn", starts("a", "b", "c", "after_join"), []),
    ],
)
def test_a_tag_the_pool_does_not_allow_there_is_flagged_where_it_happened(model, steps, where):
    assert flagged(model, steps) == where
