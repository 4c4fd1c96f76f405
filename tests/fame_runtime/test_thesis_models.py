"""The thesis authors' own engine test models run, JavaScript included, and leave the
trace their structure implies; the rest is refused at deploy time, naming the elements."""

import pytest
from fame_suite import PERSON, pair, run, trace

from robotale.errors import ModelError
from robotale.fame_runtime.library import Library
from robotale.fame_runtime.parser import parse
from robotale.fame_runtime.plan import deploy, problems


@pytest.fixture
def tests_folder(fame_models):
    return fame_models / "fame-ros" / "tests"


def test_data_model_loops_through_building_blocks_of_the_tests_folder(tests_folder):
    # Set Value: variable_name = 5, loop = 0 -> "variable > 0" -> MySecondCallActivity (Scnd:
    # variable_name = 0) -> Scnd (loop = -1) -> loop back -> "variable <= 0" -> MyCallActivity
    # (loop = 1) -> loop (loop = 1) -> "loop > 0" -> end.
    mission, tags = run(tests_folder / "data.bpmn", library=tests_folder)
    assert trace(tags) == [
        *pair(0, "paperino", "set_value"),
        (0, "paperino", "call_activity_2", "start"),
        *pair(0, "paperino", "scnd"),
        (0, "paperino", "call_activity_2", "complete"),
        *pair(0, "paperino", "scnd"),
        (0, "paperino", "call_activity", "start"),
        *pair(0, "paperino", "Activity_1"),  # unnamed: tagged with its id
        (0, "paperino", "call_activity", "complete"),
        *pair(0, "paperino", "loop"),
    ]
    variables = mission.engines["paperino"].variables
    assert (variables["x"], variables["y"], variables["ciaoname"]) == (10, 15, "paperino")
    assert (variables["variable_name"], variables["loop"]) == (0, 1)


def test_and_model_joins_two_timed_signal_throws_then_calls_a_process_of_the_file(tests_folder):
    _, tags = run(tests_folder / "and.bpmn", robots=["process_04zetxl"])
    robot = "process_04zetxl"
    assert trace(tags, messages=True) == [
        (1, robot, "timer1", "start", "", ""),
        (1, robot, "timer1", "complete", "", ""),
        (1, robot, "cmd_vel!", "start", "m_1", "send"),
        (1, robot, "cmd_vel!", "complete", "m_1", "send"),
        (1, robot, "timer2", "start", "", ""),
        (1, robot, "timer2", "complete", "", ""),
        (1, robot, "name!", "start", "m_2", "send"),
        (1, robot, "name!", "complete", "m_2", "send"),
        (1, robot, "my", "start", "", ""),
        (1, robot, "pippo", "start", "", ""),
        (1, robot, "pippo", "complete", "", ""),
        (1, robot, "name!", "start", "m_3", "send"),
        (1, robot, "name!", "complete", "m_3", "send"),
        (1, robot, "my", "complete", "", ""),
    ]
    assert (
        tags[2].payload
        == '{"linear":{"x":2.0,"y":0.0,"z":0.0},"angular":{"x":0.0,"y":0.0,"z":1.8}}'
    )
    assert tags[6].payload == '{"data":"pluto"}'


def test_rexdingo_signal_starts_dingo(fame_models):
    _, tags = run(fame_models / "fame-modeler" / "rexdingo.bpmn")
    assert [(t.robot, t.activity, t.lifecycle, t.msg_id) for t in tags] == [
        ("rex", "Activity_0nt1x8y", "start", ""),
        ("rex", "Activity_0nt1x8y", "complete", ""),
        ("rex", "ciao!", "start", "m_1"),
        ("rex", "ciao!", "complete", "m_1"),
        ("rex", "Activity_1bv1788", "start", ""),
        ("rex", "Activity_1bv1788", "complete", ""),
        ("dingo", "ciao?", "start", "m_1"),
        ("dingo", "ciao?", "complete", "m_1"),
        ("dingo", "Activity_1u2gj9k", "start", ""),
        ("dingo", "Activity_1u2gj9k", "complete", ""),
        ("dingo", "Activity_1mzyhfq", "start", ""),
        ("dingo", "Activity_1mzyhfq", "complete", ""),
    ]
    assert tags[2].payload == '{"data":false}'  # ros:parameter name="data:" value="false"


def test_process_2_each_robot_catches_its_own_signal(tests_folder):
    mission, tags = run(tests_folder / "process_2.bpmn", robots=["paperino_1", "pluto"])
    assert [(t.stamp, t.robot, t.activity, t.msg_id) for t in tags if t.lifecycle == "start"] == [
        (0, "paperino_1", "set_hello_world", ""),
        (0, "pluto", "pippo", ""),
        (5, "paperino_1", "Event_1rw6r0k", ""),
        (5, "paperino_1", "hello_world!", "m_1"),
        (5, "pluto", "Event_0iddt4k", ""),
        (5, "pluto", "cmd_vel!", "m_2"),
        (5, "paperino_1", "hello_world?", "m_1"),
        (5, "pluto", "cmd_vel?", "m_2"),
    ]
    assert mission.engines["paperino_1"].variables["hello_world"] == {"data": "Hello World!"}


NO_CONDITION = " (give its conditionalEventDefinition a bpmn:condition)"
NO_TIMER = " (give a timeDate, timeDuration or timeCycle with a value, e.g. PT10S)"


def test_general_bpmn_elements_are_refused_naming_each(fame_models):
    example = parse(fame_models / "fame-modeler" / "example.bpmn").processes["Process_1"]
    found = problems(example)
    assert sorted(found) == sorted(
        [
            "userTask Task_026c0id (Insert Card) needs a person" + PERSON,
            "userTask Task_0p47z7h (Select Amount) needs a person" + PERSON,
            "userTask Task_0po6mda (Select Interaction) needs a person" + PERSON,
            "intermediateCatchEvent IntermediateThrowEvent_02yoqsl (Cash Withdrawn) is a "
            f"conditional event without a condition{NO_CONDITION}",
            "intermediateCatchEvent IntermediateCatchEvent_12qf66u (30 seconds elapsed) is a timer "
            f"without a date, duration or cycle{NO_TIMER}",
            "intermediateCatchEvent IntermediateThrowEvent_10vhtou (Balance checked) is a "
            f"conditional event without a condition{NO_CONDITION}",
            "boundaryEvent BoundaryEvent_Timer_non_interrupting is a timer without a date, "
            f"duration or cycle{NO_TIMER}",
        ]
    )
    # its three message events run now (each waits on its pool's topic): none is refused
    messages = sorted(n.id for n in example.walk() if n.event_kind == "message")
    assert messages == [
        "BoundaryEvent_07intkn",
        "IntermediateCatchEvent_087fl8m",
        "IntermediateCatchEvent_09tc0wh",
    ]
    with pytest.raises(ModelError) as error:
        deploy(example)
    assert str(error.value).startswith(
        f"{fame_models / 'fame-modeler' / 'example.bpmn'}: the engine cannot run process "
        "Process_1: intermediateCatchEvent IntermediateThrowEvent_02yoqsl (Cash Withdrawn) is a "
        f"conditional event without a condition{NO_CONDITION} (line 49); "
    )


@pytest.mark.parametrize(
    "name",
    [
        "agri.bpmn",
        "Drone.bpmn",
        "Tractor.bpmn",
        "Tractor_1.bpmn",
        "Tractor_2.bpmn",
        "Tractor_3.bpmn",
        "GoTo.bpmn",
        "Detect.bpmn",
        "Explore.bpmn",
        "TakeOff.bpmn",
        "Land.bpmn",
        "CutGrass.bpmn",
        "ReturnToBase.bpmn",
        "REX.bpmn",
        "DINGO.bpmn",
        "simple_scenario.bpmn",
    ],
)
def test_the_ros_models_and_their_javascript_deploy_as_published(fame_models, name):
    # Their scripts and conditions are FAME's JavaScript with the rclnodejs node: every
    # process of each file, with the building blocks it calls, has nothing the engine refuses.
    folder = fame_models / "fame-ros"
    for process in parse(folder / name).processes.values():
        assert problems(process, library=Library(folder)) == []
