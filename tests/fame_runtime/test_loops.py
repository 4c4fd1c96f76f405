"""Loops and multi-instance activities in the semantics suite: exact tag traces worked out
by hand, and the same files run by SpiffWorkflow where it reads them."""

import pytest
from fame_suite import MODELS, pair, run, trace

from robotale.errors import ModelError
from robotale.fame_runtime.expressions import BpmnError
from robotale.fame_runtime.parser import parse_all_bytes, parse_bytes
from robotale.fame_runtime.plan import deploy, findings

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


HEAD = (
    '<?xml version="1.0" encoding="UTF-8"?>'
    '<bpmn:definitions xmlns:bpmn="http://www.omg.org/spec/BPMN/20100524/MODEL" id="d">'
    '<bpmn:process id="rover"><bpmn:startEvent id="start" />'
)
TAIL = (
    '<bpmn:endEvent id="end" /><bpmn:sequenceFlow id="f1" sourceRef="start" targetRef="a" />'
    '<bpmn:sequenceFlow id="f2" sourceRef="a" targetRef="end" /></bpmn:process>'
    "</bpmn:definitions>"
)


def test_a_malformed_loop_is_read_as_a_problem_and_a_bare_marker_refused_when_deployed():
    text = (
        HEAD + '<bpmn:task id="a" name="a"><bpmn:standardLoopCharacteristics loopMaximum="many"/>'
        "</bpmn:task>"
        '<bpmn:task id="b"><bpmn:multiInstanceLoopCharacteristics /></bpmn:task>' + TAIL
    )
    with pytest.raises(ModelError) as error:
        parse_bytes(text.encode(), "loops.bpmn")
    # valid BPMN: a multi-instance marker without cardinality is no reading problem
    assert str(error.value) == (
        "loops.bpmn:1: the loop of task a has loopMaximum 'many', which is no whole number "
        '(write e.g. loopMaximum="5")'
    )
    definitions = parse_all_bytes(text.encode(), "loops.bpmn")
    assert findings(definitions.processes["rover"])[-1].sentence == (
        "task b has a multi-instance marker with neither a loopCardinality nor a collection "
        "(loopDataInputRef or camunda:collection), so robotale cannot tell how many instances "
        "to run: give one, e.g. <bpmn:loopCardinality>3</bpmn:loopCardinality>"
    )


def test_a_standard_loop_without_condition_or_maximum_is_refused():
    text = HEAD + '<bpmn:task id="a"><bpmn:standardLoopCharacteristics /></bpmn:task>' + TAIL
    with pytest.raises(ModelError, match="task a has a standard loop without loopCondition or"):
        deploy(parse_bytes(text.encode()).processes["rover"])


def fail_on_two(robot, inputs, done):
    """A skill that fails with the BPMN error ``stuck`` for the item 2, else takes 5 s."""
    if robot.variables["item"] == 2:
        raise BpmnError("stuck")
    return robot.clock.call_later(5, lambda: done({})).cancel


def test_an_error_in_one_instance_is_caught_around_the_whole_activity(tmp_path):
    text = (
        HEAD + '<bpmn:error id="E" name="stuck" /><bpmn:callActivity id="a" name="work" '
        'calledElement="work"><bpmn:multiInstanceLoopCharacteristics>'
        "<bpmn:loopDataInputRef>items</bpmn:loopDataInputRef>"
        '<bpmn:inputDataItem id="item" /></bpmn:multiInstanceLoopCharacteristics>'
        '</bpmn:callActivity><bpmn:boundaryEvent id="b" attachedToRef="a">'
        '<bpmn:errorEventDefinition errorRef="E" /></bpmn:boundaryEvent>'
        '<bpmn:task id="h" name="handle" /><bpmn:endEvent id="end2" />'
        '<bpmn:sequenceFlow id="f3" sourceRef="b" targetRef="h" />'
        '<bpmn:sequenceFlow id="f4" sourceRef="h" targetRef="end2" />' + TAIL
    )
    path = tmp_path / "mi_error.bpmn"
    path.write_text(text)
    mission, tags = run(
        path, skills={"work": fail_on_two}, variables={"rover": {"items": [1, 2, 3]}}
    )
    # instance 1 starts its 5 s skill; instance 2 fails at once: the boundary cancels the
    # whole activity (instance 1's skill, instance 3 before it starts) and handle runs
    assert trace(tags) == [
        (0, "rover", "work", "start"),
        (0, "rover", "work", "start"),
        *pair(0, "rover", "stuck"),
        *pair(0, "rover", "handle"),
    ]
    assert mission.clock.next_time() is None and not mission.failures
