"""Loops and multi-instance activities in the semantics suite: exact tag traces worked out
by hand, and the same files run by SpiffWorkflow where it reads them."""

import pytest
from fame_suite import MODELS, pair, run, trace

LOOP_VARIABLES = {"fields": ["a", "b", "c"], "blinks": 3, "depths": [5, 20, 35, 50]}
LOOP_VARIABLES |= {"steps": 0, "tries": 0}


def spiff_run(path, process, variables):
    """SpiffWorkflow on the same file: (names of the tasks it completed in order, its data)."""
    from SpiffWorkflow.bpmn import BpmnWorkflow
    from SpiffWorkflow.bpmn.parser import BpmnParser
    from SpiffWorkflow.util.task import TaskState

    parser = BpmnParser()
    parser.add_bpmn_file(str(path))
    workflow = BpmnWorkflow(parser.get_spec(process))
    workflow.get_tasks()[0].data.update(variables)
    workflow.do_engine_steps()
    assert workflow.is_completed()
    done = sorted(workflow.get_tasks(state=TaskState.COMPLETED), key=lambda t: t.last_state_change)
    return [t.task_spec.bpmn_name for t in done if t.task_spec.bpmn_name], workflow.data


def test_loops_and_multi_instance_activities_run_each_instance():
    mission, tags = run("loops.bpmn", variables={"rover": dict(LOOP_VARIABLES)})
    # visit: one per field; blink: cardinality 3; sample: until a depth >= 20 (the second);
    # step: until steps reaches 3, tested after; skip: tested before, steps is 3: never;
    # retry: capped at loopMaximum 2 although its condition stays true
    counts = [("visit", 3), ("blink", 3), ("sample", 2), ("step", 3), ("retry", 2)]
    assert trace(tags) == [
        t for name, n in counts for _ in range(n) for t in pair(0, "rover", name)
    ]
    rover = mission.engines["rover"].variables
    assert rover["reports"] == ["A", "B", "C"] and rover["verdicts"] == [False, True]
    assert (rover["steps"], rover["tries"], "skipped" in rover) == (3, 2, False)


def test_loops_and_multi_instance_activities_agree_with_spiffworkflow():
    path = MODELS / "loops.bpmn"
    names, data = spiff_run(path, "rover", dict(LOOP_VARIABLES))
    mission, tags = run(path, variables={"rover": dict(LOOP_VARIABLES)})
    assert [t.activity for t in tags if t.lifecycle == "complete"] == names
    ours = mission.engines["rover"].variables
    for name in ("reports", "verdicts", "steps", "tries", "lamp"):
        assert ours[name] == data[name], name


def drive(robot, inputs, done):
    """A drive of ``target`` simulated seconds, cancellable."""
    timer = robot.clock.call_later(robot.variables["target"], lambda: done({}))
    return timer.cancel


@pytest.mark.parametrize(
    ("targets", "expected"),
    [
        # all three start at 0; 10 and 20 complete, which is two: the 30 s drive is cancelled
        ([30, 10, 20], [(10, "drive", "complete"), (20, "drive", "complete"), (20, "report")]),
        # only one drive completes before the 25 s boundary timer cancels the whole activity
        ([40, 10, 30], [(10, "drive", "complete"), (25, "too_long"), (25, "give_up")]),
    ],
)
def test_parallel_multi_instance_skill_completion_condition_and_boundary(targets, expected):
    mission, tags = run(
        "mi_drive.bpmn", skills={"drive": drive}, variables={"rover": {"targets": targets}}
    )
    want = [(0, "rover", "drive", "start")] * 3
    for step in expected:
        want += (
            [(step[0], "rover", *step[1:])] if len(step) == 3 else pair(*step[:1], "rover", step[1])
        )
    assert trace(tags) == want
    assert mission.clock.next_time() is None and mission.done
