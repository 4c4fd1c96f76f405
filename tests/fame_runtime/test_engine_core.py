"""The engine core: each model of the suite and the exact trace of tags it must leave."""

import pytest
from fame_suite import pair, run, trace

from robotale.errors import ModelError
from robotale.fame_runtime import engine as engine_module


def test_tasks_scripts_exclusive_gateway_and_data_objects():
    mission, tags = run("sequence.bpmn", variables={"rover": {"offset": 1}})
    assert trace(tags) == [
        *pair(0.0, "rover", "prepare"),
        *pair(0.0, "rover", "measure"),
        *pair(0.0, "rover", "raise_alarm"),
    ]
    engine = mission.engines["rover"]
    # threshold 10 comes from the data object, reading = 10 * 2 + 1 from the script.
    assert engine.variables["reading"] == 21 and engine.variables["alarm"] is True
    assert engine.ended and engine.completed == 1


def test_default_flow_is_taken_when_no_condition_holds():
    mission, tags = run("sequence.bpmn", variables={"rover": {"offset": 0}})
    assert [t.activity for t in tags][-2:] == ["carry_on", "carry_on"]
    assert mission.engines["rover"].variables["alarm"] is False


def test_parallel_split_runs_branches_concurrently_and_join_waits_for_both():
    mission, tags = run("parallel.bpmn")
    assert trace(tags) == [
        *pair(0.0, "rover", "b"),
        *pair(0.0, "rover", "c"),
        *pair(2.0, "rover", "wait_2_s"),
        *pair(2.0, "rover", "a"),
        *pair(2.0, "rover", "after_join"),
    ]
    variables = mission.engines["rover"].variables
    assert (variables["a"], variables["b"], variables["c"]) == (2.0, 0.0, 0.0)


def test_signals_are_topics_with_payloads_and_message_ids():
    mission, tags = run("signals.bpmn", robots=["drone", "tractor_1", "tractor_2"], latency=0.5)
    assert trace(tags, messages=True) == [
        (1.0, "drone", "1_s", "start", "", ""),
        (1.0, "drone", "1_s", "complete", "", ""),
        (1.0, "drone", "detect_weed", "start", "", ""),
        (1.0, "drone", "detect_weed", "complete", "", ""),
        (1.0, "drone", "weed_position!", "start", "m_1", "send"),
        (1.0, "drone", "weed_position!", "complete", "m_1", "send"),
        (1.5, "tractor_1", "weed_position?", "start", "m_1", "receive"),
        (1.5, "tractor_1", "weed_position?", "complete", "m_1", "receive"),
        (1.5, "tractor_1", "tractor_position!", "start", "m_2", "send"),
        (1.5, "tractor_1", "tractor_position!", "complete", "m_2", "send"),
        (1.5, "tractor_2", "weed_position?", "start", "m_1", "receive"),
        (1.5, "tractor_2", "weed_position?", "complete", "m_1", "receive"),
        (1.5, "tractor_2", "tractor_position!", "start", "m_3", "send"),
        (1.5, "tractor_2", "tractor_position!", "complete", "m_3", "send"),
        # The drone's catch takes the first message (tractor_1's); the second finds no token.
        (2.0, "drone", "tractor_position?", "start", "m_2", "receive"),
        (2.0, "drone", "tractor_position?", "complete", "m_2", "receive"),
    ]
    assert tags[4].payload == '{"x":4.0,"y":2.5,"z":0.0}'
    assert tags[8].payload == (
        '{"header":{"frame_id":"tractor_1"},"vector":{"x":3.0,"y":2.5,"z":0.0}}'
    )
    drone, tractor = mission.engines["drone"], mission.engines["tractor_2"]
    assert tractor.variables["x_weed"] == 4.0 and tractor.variables["y_weed"] == 2.5
    assert drone.variables["first_tractor"] == "tractor_1" and drone.variables["first_x"] == 3.0
    assert mission.done and all(e.completed == 1 for e in mission.engines.values())


def navigate(robot, inputs, done):
    """A skill that drives for |goal - start| / speed simulated seconds."""
    distance = abs(inputs["x_goal"] - 0.0) + abs(inputs["y_goal"] - 0.0) - 2.0
    timer = robot.clock.call_later(
        distance / inputs["speed"], lambda: done({"arrival": robot.now(), "distance": distance})
    )
    return timer.cancel


def test_call_activities_library_same_file_and_skill_with_inputs_and_outputs():
    mission, tags = run(
        "calls.bpmn",
        skills={"navigate": navigate},
        variables={"rover": {"home_y": 0.0, "top_speed": 2.5}},
    )
    assert trace(tags) == [
        (0.0, "rover", "blink", "start"),
        *pair(0.0, "rover", "led_on"),
        *pair(1.0, "rover", "1_s"),
        *pair(1.0, "rover", "led_off"),
        (1.0, "rover", "blink", "complete"),
        (1.0, "rover", "charge", "start"),
        *pair(1.0, "rover", "plug_in"),
        (1.0, "rover", "charge", "complete"),
        # inputs: x_goal 3 + y_goal 4 - 2 = distance 5, speed 2.5 / 2: 4 seconds
        (1.0, "rover", "go_to_goal", "start"),
        (5.0, "rover", "go_to_goal", "complete"),
        *pair(5.0, "rover", "celebrate"),
    ]
    variables = mission.engines["rover"].variables
    assert variables["arrived_at"] == 5.0 and variables["charged"] is True
    assert (variables["x_goal"], variables["y_goal"], variables["speed"]) == (3.0, 4.0, 1.25)


def test_skill_gets_the_robot_handle_and_read_only_inputs():
    seen = {}

    def look(robot, inputs, done):
        seen.update(name=robot.name, type=robot.robot_type, topic=robot.topic("odom"))
        with pytest.raises(TypeError):
            inputs["speed"] = 0  # type: ignore[index]
        done({"arrival": 5.0, "distance": 5.0})

    _, tags = run(
        "calls.bpmn", skills={"navigate": look}, variables={"rover": {"home_y": 0, "top_speed": 1}}
    )
    assert seen == {"name": "rover", "type": "Rover", "topic": "/rover/odom"}
    assert tags[-1].activity == "celebrate"


def test_terminate_ends_every_token_of_the_process():
    mission, tags = run("terminate.bpmn")
    assert trace(tags) == [*pair(1.0, "rover", "1_s"), *pair(1.0, "rover", "quick")]
    engine = mission.engines["rover"]
    assert engine.ended and "late" not in engine.variables
    assert mission.clock.next_time() is None  # the 5 s timer was cancelled, not left behind


def test_unknown_called_element_is_refused_at_deploy(models):
    with pytest.raises(ModelError, match=r"callActivity go \(Go To Goal\) calls 'navigate'"):
        run("calls.bpmn", skills={})


def test_a_failing_skill_or_script_is_a_model_error_naming_the_element():
    def broken(robot, inputs, done):
        raise KeyError("x_goal")

    variables = {"rover": {"home_y": 0, "top_speed": 1}}
    with pytest.raises(
        ModelError,
        match=r"robot rover: skill 'navigate' of call activity go \(Go To Goal\) failed: "
        r"KeyError: 'x_goal'",
    ):
        run("calls.bpmn", skills={"navigate": broken}, variables=variables)
    with pytest.raises(
        ModelError,
        match=r"robot rover: script task measure \(Measure\) failed: NameError: "
        r"name 'offset' is not defined",
    ):
        run("sequence.bpmn")


def test_a_skill_that_calls_done_twice_or_after_cancel_is_ignored():
    calls = []

    def twice(robot, inputs, done):
        done({"arrival": 5.0, "distance": 5.0})
        done({"arrival": 99.0, "distance": 0.0})
        calls.append(robot.now())

    mission, tags = run(
        "calls.bpmn", skills={"navigate": twice}, variables={"rover": {"home_y": 0, "top_speed": 1}}
    )
    assert [t.activity for t in tags].count("celebrate") == 2  # one start, one complete
    assert mission.engines["rover"].variables["arrived_at"] == 5.0 and calls == [1.0]


def test_a_loop_that_never_waits_is_a_model_error_not_a_hang(tmp_path, monkeypatch):
    monkeypatch.setattr(engine_module, "MAX_STEPS", 1000)
    path = tmp_path / "spin.bpmn"
    path.write_text(
        '<bpmn:definitions xmlns:bpmn="http://www.omg.org/spec/BPMN/20100524/MODEL" id="d">'
        '<bpmn:process id="Rover"><bpmn:startEvent id="s" />'
        '<bpmn:exclusiveGateway id="again" name="again?" />'
        '<bpmn:scriptTask id="spin" name="Spin"><bpmn:script>turns = 1</bpmn:script>'
        "</bpmn:scriptTask>"
        '<bpmn:sequenceFlow id="a" sourceRef="s" targetRef="again" />'
        '<bpmn:sequenceFlow id="b" sourceRef="again" targetRef="spin" />'
        '<bpmn:sequenceFlow id="c" sourceRef="spin" targetRef="again" />'
        "</bpmn:process></bpmn:definitions>"
    )
    with pytest.raises(ModelError, match="in a loop that ran 1000 steps without waiting"):
        run(path)
