"""The parser reads the thesis authors' own models, quirks included, and explains bad ones."""

from pathlib import Path

import pytest
from fame_suite import run

from robotale.errors import ModelError
from robotale.fame_runtime.parser import parse
from robotale.fame_runtime.plan import deploy
from robotale.fame_runtime.qos import QoS
from robotale.fame_runtime.splitter import split

THESIS_FILES = 30


def test_every_thesis_model_parses(fame_models):
    files = sorted(fame_models.rglob("*.bpmn"))
    assert len(files) == THESIS_FILES
    for path in files:
        definitions = parse(path)
        assert definitions.processes, path
        for _, process in definitions.pools():
            assert list(process.walk()), f"{path}: {process.id} has no elements"


def test_agri_collaboration_pools_signals_and_camunda_configuration(fame_models):
    agri = parse(fame_models / "fame-ros" / "agri.bpmn")
    pools = {pool.name: (pool, process) for pool, process in agri.pools()}
    assert set(pools) == {"Drone", "Tractor"}
    tractor_pool, tractor = pools["Tractor"]
    assert tractor_pool.multi_instance and (tractor_pool.minimum, tractor_pool.maximum) == (1, 3)
    start = tractor.nodes["Event_0ic1bhm"]
    assert (start.kind, start.event_kind, start.event.ref_name) == (
        "startEvent",
        "signal",
        "weed_position",
    )
    assert start.message.msgtype == "geometry_msgs/msg/Vector3"
    assert start.data_outputs == ["DataObjectReference_0rl7dt5"]
    weed = tractor.data_objects["DataObjectReference_0rl7dt5"]
    assert weed.parameters == {"x_weed": "${x_weed}", "y_weed": "${y_weed}"}
    _, drone = pools["Drone"]
    handler = drone.nodes["Activity_0yfgd02"]
    assert handler.triggered_by_event and "Event_0hgkc9o" in handler.scope.nodes
    throw = handler.scope.nodes["Event_0hgkc9o"]
    assert throw.message.payload == '{"x": ${x_weed}, "y": ${y_weed}, "z":  ${z_weed}}'
    timer = tractor.nodes["Event_0ixc6v0"].event.timer
    assert (timer.kind, timer.interval) == ("timeDuration", 30.0)
    no_flow = tractor.flows["Flow_1bz8ltf"]
    assert no_flow.condition.language == "javascript" and no_flow.name == "No"


def test_signal_referenced_before_its_declaration(fame_models):
    detect = parse(fame_models / "fame-ros" / "Detect.bpmn").processes["Detect"]
    end = detect.nodes["EndThrow_target_found"]
    assert end.event.ref == "Signal_1j8ltra" and end.event.ref_name == "target_found"


def test_missing_signal_definition_keeps_the_event(fame_models):
    throwcatch = parse(fame_models / "fame-ros" / "tests" / "throwcatch.bpmn")
    catch = throwcatch.processes["Process_0cqv1zc"].nodes["ciao"]
    assert catch.event_kind == "signal" and catch.event.ref == "" and catch.event.ref_name == ""


def test_thesis_ros_flavour_and_camunda_input_output_flavour(fame_models):
    rexdingo = parse(fame_models / "fame-modeler" / "rexdingo.bpmn")
    throw = rexdingo.processes["Process_1vrsp9u"].nodes["Event_03upc5q"]
    assert throw.message.msgtype == "std_msgs/msg/Bool"
    assert throw.message.payload == {"data": "false"}  # the authors wrote name="data:"
    and_model = parse(fame_models / "fame-ros" / "tests" / "and.bpmn")
    velocity = and_model.processes["Process_04zetxl"].nodes["vel_sig"]
    assert velocity.message.msgtype == "geometry_msgs/msg/Twist"
    assert velocity.message.payload.startswith('{"linear": {"x": 2.0')


def test_thesis_listings_data_and_qos_extension_elements(tmp_path):
    # Listings 5.1, 5.2 and 5.7 of the thesis, as FAME-modeler writes them.
    path = tmp_path / "listings.bpmn"
    path.write_text(
        f"""<bpmn:definitions {NS} xmlns:data="http://fame/data" xmlns:ros="http://fame/ros"
            xmlns:qos="http://fame/qos" id="d">
      <bpmn:process id="p">
        <bpmn:dataObjectReference id="DataObjectReference_17784gh"
            dataObjectRef="DataObject_0wt07gj">
          <bpmn:extensionElements><data:parameters>
            <data:parameter name="variable_1" value="${{variable_1}}" />
            <data:parameter name="variable_2" value="50" />
          </data:parameters></bpmn:extensionElements>
        </bpmn:dataObjectReference>
        <bpmn:dataObject id="DataObject_0wt07gj" />
        <bpmn:intermediateThrowEvent id="Event_00tbq5g" name="topic_name">
          <bpmn:extensionElements>
            <ros:message type="geometry_msgs/msg/Vector3" />
            <ros:payload>
              <ros:parameter name="x" value="5.0" /><ros:parameter name="y" value="2.1" />
              <ros:parameter name="z" value="0.0" />
            </ros:payload>
            <qos:policy name="history" value="keep_last" /><qos:policy name="depth" value="5" />
            <qos:policy name="reliability" value="reliable" />
            <qos:policy name="durability" value="transient_local" />
            <qos:policy name="deadline" value="2" /><qos:policy name="lifespan" value="10" />
            <qos:policy name="liveliness" value="automatic" />
            <qos:policy name="lease_duration" value="10" />
          </bpmn:extensionElements>
          <bpmn:signalEventDefinition />
        </bpmn:intermediateThrowEvent>
      </bpmn:process></bpmn:definitions>"""
    )
    process = parse(path).processes["p"]
    assert process.data_objects["DataObjectReference_17784gh"].parameters == {
        "variable_1": "${variable_1}",
        "variable_2": "50",
    }
    message = process.nodes["Event_00tbq5g"].message
    assert message.payload == {"x": "5.0", "y": "2.1", "z": "0.0"}
    assert message.qos == QoS(
        "reliable", "transient_local", "keep_last", 5, 2.0, 10.0, "automatic", 10.0
    )


def test_agri_splits_into_drone_and_tractors(fame_models):
    agri = parse(fame_models / "fame-ros" / "agri.bpmn")
    robots = ["tractor_3", "drone", "Tractor_1", "tractor_2"]
    assignments = split(agri, robots)
    assert [(a.robot, a.robot_type, a.process.id) for a in assignments] == [
        ("Tractor_1", "Tractor", "Process_169rpm3"),
        ("tractor_2", "Tractor", "Process_169rpm3"),
        ("tractor_3", "Tractor", "Process_169rpm3"),
        ("drone", "Drone", "drone_process"),
    ]
    assert [a.robot for a in split(agri)] == ["tractor_1", "drone"]
    with pytest.raises(ModelError, match="at most 3 robots, 4 given"):
        split(agri, ["drone", "tractor_1", "tractor_2", "tractor_3", "tractor_4"])
    with pytest.raises(ModelError, match="robot rover matches no pool"):
        split(agri, ["drone", "tractor_1", "rover"])
    with pytest.raises(ModelError, match="pool Tractor needs at least 1 robot, 0 given"):
        split(agri, ["drone"])


NS = (
    'xmlns:bpmn="http://www.omg.org/spec/BPMN/20100524/MODEL" '
    'xmlns:xsi="http://www.w3.org/2001/XMLSchema-instance"'
)


def refusal(call, *args, **kwargs) -> str:
    """The message of the ModelError ``call`` raises."""
    with pytest.raises(ModelError) as error:
        call(*args, **kwargs)
    return str(error.value)


def bad_model(tmp_path: Path, body: str) -> Path:
    path = tmp_path / "bad.bpmn"
    path.write_text(
        f'<bpmn:definitions {NS} id="d">\n<bpmn:process id="p">\n{body}\n'
        "</bpmn:process>\n</bpmn:definitions>\n"
    )
    return path


def test_dangling_sequence_flow_names_the_flow_and_line(tmp_path):
    path = bad_model(
        tmp_path,
        '<bpmn:startEvent id="s" />\n'
        '<bpmn:sequenceFlow id="Flow_9" sourceRef="s" targetRef="gone" />',
    )
    assert refusal(parse, path) == (
        f"{path}:4: sequence flow Flow_9 is dangling: its target (gone) is not an element of "
        "the same process or sub-process"
    )


def test_gateway_without_outgoing_flow_is_refused_naming_it(tmp_path):
    path = bad_model(
        tmp_path,
        '<bpmn:startEvent id="s" /><bpmn:exclusiveGateway id="Gateway_7" name="which way?" />'
        '<bpmn:sequenceFlow id="f" sourceRef="s" targetRef="Gateway_7" />',
    )
    assert refusal(deploy, parse(path).processes["p"]) == (
        f"{path}: the engine cannot run process p: exclusiveGateway Gateway_7 (which way?) "
        "has no outgoing sequence flow (give it at least one) (line 3)"
    )


def test_unknown_called_element_is_refused_naming_it(tmp_path):
    path = bad_model(
        tmp_path,
        '<bpmn:startEvent id="s" />'
        '<bpmn:callActivity id="Call_1" name="Fly" calledElement="FlyAway" />'
        '<bpmn:sequenceFlow id="f" sourceRef="s" targetRef="Call_1" />',
    )
    message = refusal(deploy, parse(path).processes["p"], skills={"navigate"})
    assert message == (
        f"{path}: the engine cannot run process p: callActivity Call_1 (Fly) calls 'FlyAway', "
        "which is no skill, no process of the file (name one of those) (line 3)"
    )


@pytest.mark.parametrize(
    ("definition", "complaint"),
    [
        ("<bpmn:timeDuration>PT5X</bpmn:timeDuration>", "'PT5X' is not an ISO 8601 duration"),
        ("<bpmn:timeCycle>every 5 s</bpmn:timeCycle>", "'every 5 s' is not an ISO 8601 cycle"),
        ("<bpmn:timeDate>tomorrow</bpmn:timeDate>", "'tomorrow' is not an ISO 8601 date-time"),
    ],
)
def test_malformed_timer_names_the_event(tmp_path, definition, complaint):
    path = bad_model(
        tmp_path,
        f'<bpmn:intermediateCatchEvent id="Timer_3" name="wait">\n'
        f"<bpmn:timerEventDefinition>{definition}</bpmn:timerEventDefinition>\n"
        "</bpmn:intermediateCatchEvent>",
    )
    assert refusal(parse, path).startswith(
        f"{path}:4: timer event Timer_3 (wait) is malformed: {complaint}"
    )


def test_malformed_xml_names_file_and_line(tmp_path):
    path = tmp_path / "broken.bpmn"
    path.write_text(
        f'<bpmn:definitions {NS}>\n<bpmn:process id="p">\n<bpmn:task id="t">\n</bpmn:definitions>\n'
    )
    with pytest.raises(ModelError, match=rf"^{path}:4: malformed XML: "):
        parse(path)


def test_not_bpmn_and_missing_file(tmp_path):
    path = tmp_path / "other.xml"
    path.write_text("<svg/>")
    with pytest.raises(ModelError, match=r"not a BPMN 2\.0 file: the root element is svg"):
        parse(path)
    with pytest.raises(ModelError, match="cannot read the BPMN file"):
        parse(tmp_path / "missing.bpmn")


def test_call_activity_with_the_process_embedded_as_in_listing_5_6(tmp_path):
    embedded = (
        "&lt;bpmn:process id='Process_GoTo' isExecutable='true'&gt;"
        "&lt;bpmn:startEvent id='s' /&gt;"
        "&lt;bpmn:scriptTask id='go' name='Go'&gt;&lt;bpmn:script&gt;went = True"
        "&lt;/bpmn:script&gt;&lt;/bpmn:scriptTask&gt;"
        "&lt;bpmn:endEvent id='e' /&gt;"
        "&lt;bpmn:sequenceFlow id='a' sourceRef='s' targetRef='go' /&gt;"
        "&lt;bpmn:sequenceFlow id='b' sourceRef='go' targetRef='e' /&gt;"
        "&lt;/bpmn:process&gt;"
    )
    path = tmp_path / "embedded.bpmn"
    path.write_text(
        f"""<bpmn:definitions {NS} xmlns:callActivity="http://fame/callActivity" id="d">
      <bpmn:process id="Rover">
        <bpmn:startEvent id="start" />
        <bpmn:callActivity id="Activity_1rktq6o" name="GoTo" calledElement="GoTo">
          <bpmn:extensionElements>
            <callActivity:process process="{embedded}" />
          </bpmn:extensionElements>
        </bpmn:callActivity>
        <bpmn:endEvent id="end" />
        <bpmn:sequenceFlow id="f1" sourceRef="start" targetRef="Activity_1rktq6o" />
        <bpmn:sequenceFlow id="f2" sourceRef="Activity_1rktq6o" targetRef="end" />
      </bpmn:process></bpmn:definitions>"""
    )
    call = parse(path).processes["Rover"].nodes["Activity_1rktq6o"]
    assert call.embedded_process.id == "Process_GoTo"
    assert list(call.embedded_process.nodes) == ["s", "go", "e"]
    mission, tags = run(path)
    assert [(t.activity, t.lifecycle) for t in tags] == [
        ("go_to", "start"),
        ("go", "start"),
        ("go", "complete"),
        ("go_to", "complete"),
    ]
    assert mission.engines["rover"].variables["went"] is True
