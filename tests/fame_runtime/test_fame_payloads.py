"""How a caught signal's payload reaches the variables in FAME's JavaScript dialect: each field
goes to the first variable whose name starts with the field's name, as FAME's own engine
stores it (fame-ros ``controller.js``, ``camundaExtProperties``). DINGO's ``x_target`` gets
the ``x`` of REX's ``target_found`` this way. Robotale's Python dialect keeps its own rule."""

from pathlib import Path

from fame_suite import pair, run, trace

CATCHER_SCRIPT = {
    "javascript": "this.environment.variables.seen = this.environment.variables.x_target; next();",
    "python": "seen = x_target",
}


def collaboration(tmp_path: Path, parameters: str, *, fmt: str = "javascript") -> Path:
    """REX throws ``target_found`` {"x": 0.3, "y": 0.4, "z": 0.0}; DINGO starts on it, its
    data object ``target_position`` (``parameters``) linked by a data output association, then
    runs one script in ``fmt``."""
    payload = "{&#34;x&#34;: 0.3, &#34;y&#34;: 0.4, &#34;z&#34;: 0.0}"
    properties = "".join(
        f'<camunda:property name="{name}" value="{value}" />'
        for name, value in (p.split("=", 1) for p in parameters.split())
    )
    path = tmp_path / "payload.bpmn"
    path.write_text(
        '<?xml version="1.0" encoding="UTF-8"?>'
        '<bpmn:definitions xmlns:bpmn="http://www.omg.org/spec/BPMN/20100524/MODEL" '
        'xmlns:camunda="http://camunda.org/schema/1.0/bpmn" id="d">'
        '<bpmn:collaboration id="c">'
        '<bpmn:participant id="p1" name="REX" processRef="rex" />'
        '<bpmn:participant id="p2" name="DINGO" processRef="dingo" />'
        "</bpmn:collaboration>"
        '<bpmn:process id="rex" isExecutable="true"><bpmn:startEvent id="r0" />'
        '<bpmn:endEvent id="found" name="target_found"><bpmn:extensionElements>'
        '<camunda:properties><camunda:property name="type" value="geometry_msgs/msg/Vector3" />'
        f'<camunda:property name="payload" value="{payload}" /></camunda:properties>'
        '</bpmn:extensionElements><bpmn:signalEventDefinition signalRef="sig" /></bpmn:endEvent>'
        '<bpmn:sequenceFlow id="r1" sourceRef="r0" targetRef="found" /></bpmn:process>'
        '<bpmn:process id="dingo" isExecutable="true">'
        '<bpmn:startEvent id="catch" name="target_found"><bpmn:extensionElements>'
        '<camunda:properties><camunda:property name="type" value="geometry_msgs/msg/Vector3" />'
        "</camunda:properties></bpmn:extensionElements>"
        "<bpmn:dataOutputAssociation><bpmn:targetRef>target</bpmn:targetRef>"
        '</bpmn:dataOutputAssociation><bpmn:signalEventDefinition signalRef="sig" />'
        "</bpmn:startEvent>"
        '<bpmn:dataObjectReference id="target" name="target_position" dataObjectRef="obj">'
        f"<bpmn:extensionElements><camunda:properties>{properties}</camunda:properties>"
        '</bpmn:extensionElements></bpmn:dataObjectReference><bpmn:dataObject id="obj" />'
        f'<bpmn:scriptTask id="use" name="Use" scriptFormat="{fmt}">'
        f"<bpmn:script>{CATCHER_SCRIPT[fmt]}</bpmn:script></bpmn:scriptTask>"
        '<bpmn:endEvent id="d_end" />'
        '<bpmn:sequenceFlow id="d1" sourceRef="catch" targetRef="use" />'
        '<bpmn:sequenceFlow id="d2" sourceRef="use" targetRef="d_end" />'
        '</bpmn:process><bpmn:signal id="sig" name="target_found" /></bpmn:definitions>'
    )
    return path


def test_each_field_goes_to_the_first_variable_starting_with_its_name(tmp_path):
    # DINGO.bpmn's target_position: x_target = ${x_target}, y_target = ${y_target}
    path = collaboration(tmp_path, "x_target=${x_target} y_target=${y_target}")
    mission, tags = run(path)
    dingo = mission.engines["dingo"].variables
    assert (dingo["x_target"], dingo["y_target"], dingo["seen"]) == (0.3, 0.4, 0.3)
    assert "z" not in dingo and "z_target" not in dingo  # no variable starts with "z"
    assert dingo["target_found"] == {"x": 0.3, "y": 0.4, "z": 0.0}
    assert [t[1:] for t in trace(tags) if t[1] == "dingo"] == [
        (r, a, lc) for _, r, a, lc in [*pair(0, "dingo", "target_found?"), *pair(0, "dingo", "use")]
    ]


def test_the_first_variable_in_the_order_they_were_set_wins(tmp_path):
    # x_target then x_later are declared: FAME's find() over the environment's keys takes
    # x_target; x_later keeps what its declaration gave it
    path = collaboration(tmp_path, "x_target=${x_target} x_later=${x_later} label=weed")
    mission, _ = run(path)
    dingo = mission.engines["dingo"].variables
    assert dingo["x_target"] == 0.3 and dingo["x_later"] is None
    assert dingo["label"] == "weed"  # a literal starting with no field's name is untouched


def test_robotales_python_dialect_does_not_match_by_prefix(tmp_path):
    # a Python model names its fields in the data object: x_target = ${x}
    path = collaboration(tmp_path, "x_target=${x} y_target=${y_target}", fmt="python")
    mission, _ = run(path)
    dingo = mission.engines["dingo"].variables
    assert dingo["x_target"] == 0.3 and dingo["seen"] == 0.3
    assert dingo["y_target"] is None  # declared, never set: no prefix rule outside FAME's dialect
