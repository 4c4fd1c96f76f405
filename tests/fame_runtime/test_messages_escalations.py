"""Messages between pools and escalation events in the semantics suite: exact tag traces
worked out by hand; the escalations also run by SpiffWorkflow on the same file."""

import pytest
from fame_suite import MODELS, build, pair, run, trace

from robotale.errors import ModelError
from robotale.fame_runtime.labels import activity_label
from robotale.fame_runtime.parser import parse_bytes
from robotale.fame_runtime.plan import deploy


def test_send_and_receive_tasks_and_message_events_go_to_the_pool_of_the_message_flow():
    mission, tags = build("messages.bpmn")
    published = []
    mission.bus.tap(lambda envelope: published.append((envelope.topic, envelope.sender)))
    mission.run()
    assert trace(tags, messages=True) == [
        (1, "base", "1_s", "start", "", ""),
        (1, "base", "1_s", "complete", "", ""),
        (1, "base", "send_order", "start", "m_1", "send"),
        (1, "base", "send_order", "complete", "m_1", "send"),
        (1, "rover", "await_order", "start", "m_1", "receive"),
        (1, "rover", "await_order", "complete", "m_1", "receive"),
        (1, "rover", "work", "start", "", ""),
        (1, "rover", "work", "complete", "", ""),
        (1, "rover", "done!", "start", "m_2", "send"),
        (1, "rover", "done!", "complete", "m_2", "send"),
        (1, "base", "done?", "start", "m_2", "receive"),
        (1, "base", "done?", "complete", "m_2", "receive"),
    ]
    # point to point: each message on the receiving pool's own topic
    assert published == [("/rover/order", "base"), ("/base/done", "rover")]
    assert mission.done and not mission.failures


def test_a_message_without_a_message_flow_is_refused_naming_the_sender():
    text = (MODELS / "messages.bpmn").read_bytes().replace(b'id="mf_order"', b'id="mf_x"')
    text = text.replace(b'sourceRef="send_order" targetRef="await_order"', b'sourceRef="x"')
    base = parse_bytes(text, "messages.bpmn").processes["base"]
    with pytest.raises(
        ModelError,
        match=r"sendTask send_order \(send order\) sends message order but"
        " no message flow leads from it to another pool",
    ):
        deploy(base)


def survey(robot, *, interrupting):
    """The survey escalating low battery to its boundary event, then what follows."""
    head = [(0, robot, "survey", "start"), *pair(0, robot, "scan")]
    head += pair(0, robot, "low_battery") + pair(0, robot, "low_battery")  # thrown, caught
    if interrupting:  # the survey is cancelled: only the boundary's path goes on
        return head + pair(0, robot, "notify")
    # the thrower goes on and the survey completes before the queued boundary path runs
    tail = [*pair(0, robot, "finish_scan"), (0, robot, "survey", "complete")]
    return head + tail + pair(0, robot, "notify") + pair(0, robot, "dock")


def handler(robot, name, event, work):
    """An event sub-process ``name``: its start ``event`` caught, then it starts."""
    return [*pair(0, robot, event), (0, robot, name, "start"), *pair(0, robot, work)]


def test_escalations_caught_by_boundary_events_and_event_sub_processes():
    mission, tags = run("escalations.bpmn")
    patrol = [*pair(0, "patrol", "patrol"), *pair(0, "patrol", "obstacle")]
    patrol += handler("patrol", "handler", "obstacle", "resume")
    patrol += pair(0, "patrol", "log_obstacle")
    patrol += [(0, "patrol", "handler", "complete")]
    # halt: the escalation end event starts the interrupting handler, which cancels the
    # 10 s timer of the other branch: nothing happens at 10 s
    halt = [*pair(0, "halt", "push"), *pair(0, "halt", "stuck")]
    halt += [*handler("halt", "unstick", "stuck", "back_off"), (0, "halt", "unstick", "complete")]
    assert trace(tags) == (
        survey("gentle", interrupting=False) + survey("strict", interrupting=True) + patrol + halt
    )
    assert mission.done and mission.clock.now() == 0 and not mission.failures


def spiff_completed(process):
    """The names of the activities SpiffWorkflow completes running ``process``."""
    from SpiffWorkflow.bpmn import BpmnWorkflow
    from SpiffWorkflow.bpmn.parser import BpmnParser
    from SpiffWorkflow.util.task import TaskState

    parser = BpmnParser()
    parser.add_bpmn_file(str(MODELS / "escalations.bpmn"))
    workflow = BpmnWorkflow(parser.get_spec(process), parser.get_subprocess_specs(process))
    workflow.do_engine_steps()
    assert workflow.is_completed()
    tasks = workflow.get_tasks(state=TaskState.COMPLETED)
    return sorted(activity_label(t.task_spec.bpmn_name) for t in tasks if t.task_spec.bpmn_name)


@pytest.mark.parametrize("process", ["gentle", "patrol"])
def test_non_interrupting_escalations_run_the_same_activities_as_spiffworkflow(process):
    _, tags = run("escalations.bpmn")
    events = {"low_battery", "obstacle", "stuck"}
    ours = [t.activity for t in tags if t.robot == process and t.lifecycle == "complete"]
    assert sorted(a for a in ours if a not in events) == spiff_completed(process)


def test_interrupting_escalation_boundary_cancels_at_once_where_spiffworkflow_finishes_first():
    """BPMN 2.0 section 10.5.4: an interrupting boundary event cancels its activity when it
    fires. SpiffWorkflow 3 lets the sub-process finish first (its 'finish scan' runs)."""
    _, tags = run("escalations.bpmn")
    ours = sorted(
        t.activity
        for t in tags
        if t.robot == "strict" and t.lifecycle == "complete" and t.activity != "low_battery"
    )
    assert ours == ["notify", "scan"]
    assert spiff_completed("strict") == ["finish_scan", "notify", "scan", "survey"]
