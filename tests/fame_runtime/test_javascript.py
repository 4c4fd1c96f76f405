"""FAME's JavaScript: each construct of the authors' scripts in a small model, its exact trace
and the values a hand computation gives."""

from html import escape
from pathlib import Path

import pytest
from fame_suite import pair, run, trace

from robotale.errors import ModelError
from robotale.fame_runtime import javascript


def model(tmp_path: Path, *scripts: str, condition: str = "", fmt: str = "javascript") -> Path:
    """A process: start, one script task per script (``s1``, ``s2`` ...), then, with a
    ``condition``, an exclusive gateway to ``yes`` (when it holds) or ``no`` (default)."""
    tasks = "".join(
        f'<bpmn:scriptTask id="s{i}" name="S{i}" scriptFormat="{fmt}">'
        f"<bpmn:script>{escape(text)}</bpmn:script></bpmn:scriptTask>"
        for i, text in enumerate(scripts, 1)
    )
    chain = ["start", *(f"s{i}" for i in range(1, len(scripts) + 1))]
    targets = [*chain[1:], "gate" if condition else "end"]
    flows = "".join(
        f'<bpmn:sequenceFlow id="f{i}" sourceRef="{a}" targetRef="{b}" />'
        for i, (a, b) in enumerate(zip(chain, targets, strict=True))
    )
    gate = ""
    if condition:
        gate = (
            '<bpmn:exclusiveGateway id="gate" default="to_no" />'
            '<bpmn:task id="yes" name="Yes" /><bpmn:task id="no" name="No" />'
            '<bpmn:sequenceFlow id="to_yes" sourceRef="gate" targetRef="yes">'
            f'<bpmn:conditionExpression language="JavaScript">{escape(condition)}'
            "</bpmn:conditionExpression></bpmn:sequenceFlow>"
            '<bpmn:sequenceFlow id="to_no" sourceRef="gate" targetRef="no" />'
            '<bpmn:sequenceFlow id="y_end" sourceRef="yes" targetRef="end" />'
            '<bpmn:sequenceFlow id="n_end" sourceRef="no" targetRef="end" />'
        )
    path = tmp_path / "js.bpmn"
    path.write_text(
        '<?xml version="1.0" encoding="UTF-8"?>'
        '<bpmn:definitions xmlns:bpmn="http://www.omg.org/spec/BPMN/20100524/MODEL" id="d">'
        '<bpmn:collaboration id="c"><bpmn:participant id="p" name="Rover" processRef="rover" />'
        '</bpmn:collaboration><bpmn:process id="rover" isExecutable="true">'
        f'<bpmn:startEvent id="start" />{tasks}{gate}<bpmn:endEvent id="end" />{flows}'
        "</bpmn:process></bpmn:definitions>"
    )
    return path


def test_environment_variables_var_const_let_math_parse_float_arrays_objects(tmp_path):
    script = """
        var v = this.environment.variables;
        const base = parseFloat(v.text) + parseInt("2");
        let points = new Array();
        for (let i = 0; i < 3; i++) { points.push({x: i, y: Math.pow(i, 2)}); }
        v.points = points;
        v.distance = Math.sqrt(Math.pow(3, 2) + Math.pow(4, 2)) + base;
        v.first = points.shift();
        next();
    """
    mission, tags = run(model(tmp_path, script), variables={"rover": {"text": "1.5"}})
    assert trace(tags) == pair(0.0, "rover", "s1")
    variables = mission.engines["rover"].variables
    assert variables["distance"] == 5 + 1.5 + 2
    # shift() changed the array the variable holds, as in JavaScript
    assert variables["points"] == [{"x": 1, "y": 1}, {"x": 2, "y": 4}]
    assert variables["first"] == {"x": 0, "y": 0}


def test_an_array_changed_in_place_through_an_alias_is_seen_by_python(tmp_path):
    # Explore.bpmn: var points = variables.map_points; points.shift();
    script = "var points = this.environment.variables.map_points; points.shift(); next();"
    mission, _ = run(model(tmp_path, script), variables={"rover": {"map_points": [1, 2, 3]}})
    assert mission.engines["rover"].variables["map_points"] == [2, 3]


def test_python_and_javascript_scripts_share_the_variables(tmp_path):
    path = model(tmp_path, "this.environment.variables.a = 20; next();", "b = a + 1", "x")
    text = path.read_text().replace(
        'id="s2" name="S2" scriptFormat="javascript"', 'id="s2" name="S2" scriptFormat="python"'
    )
    path.write_text(
        text.replace(
            'id="s3" name="S3" scriptFormat="javascript"><bpmn:script>x',
            'id="s3" name="S3"><bpmn:script>next(null); environment.variables.c = '
            "environment.variables.b * 2",
        )
    )
    mission, tags = run(path)
    assert [t[2] for t in trace(tags)] == ["s1", "s1", "s2", "s2", "s3", "s3"]
    variables = mission.engines["rover"].variables
    assert (variables["a"], variables["b"], variables["c"]) == (20, 21, 42)


@pytest.mark.parametrize(
    ("condition", "x", "taken"),
    [
        ("next(null, this.environment.variables.x > 1);", 2, "yes"),
        ("next(null, this.environment.variables.x > 1);", 1, "no"),
        ("next(null, !this.environment.variables.flag);", 0, "yes"),
        ("next(null,this.environment.variables.list.length <= 0);", 0, "no"),
        ("this.environment.variables.x === 3", 3, "yes"),
        ("next(null, this.environment.variables.missing == null);", 0, "yes"),
    ],
)
def test_conditions_take_the_value_passed_to_next(tmp_path, condition, x, taken):
    variables = {"rover": {"x": x, "flag": False, "list": [1]}}
    _, tags = run(model(tmp_path, "next();", condition=condition), variables=variables)
    assert trace(tags) == [*pair(0.0, "rover", "s1"), *pair(0.0, "rover", taken)]


def test_namespace_of_the_node_as_the_agri_tractors_compare_it(tmp_path):
    condition = (
        "next(null, this.environment.variables.tractor === "
        "this.environment.variables.node.namespace().replace('/', ''));"
    )
    path = model(tmp_path, "next();", condition=condition)
    for name, taken in (("rover", "yes"), ("tractor_2", "no")):
        _, tags = run(path, variables={"rover": {"tractor": name}})
        assert trace(tags)[-1] == (0.0, "rover", taken, "complete")


def test_console_log_goes_to_the_run_output(tmp_path, capsys):
    run(model(tmp_path, 'console.log("weed at", {x: 1}, 2); next();'))
    assert capsys.readouterr().out == '[rover] weed at {"x":1} 2\n'


def test_a_task_completes_only_when_next_is_called_from_a_subscription(tmp_path):
    # Detect.bpmn: the callback sets a variable, destroys its subscription, then next().
    script = """
        const node = this.environment.variables.ros_node;
        const sub = node.createSubscription("sensor_msgs/msg/Range", "range", (msg) => {
            this.environment.variables.range = msg.range;
            node.destroySubscription(sub);
            next();
        });
    """
    mission, tags = run(model(tmp_path, script, "next();"), until=5.0)
    engine = mission.engines["rover"]
    assert trace(tags) == [(0.0, "rover", "s1", "start")]
    mission.clock.call_later(
        2.0,
        lambda: mission.bus.publish(
            "/rover/range", {"range": 0.7}, msgtype="sensor_msgs/msg/Range"
        ),
    )
    mission.clock.call_later(
        3.0,
        lambda: mission.bus.publish(
            "/rover/range", {"range": 9.0}, msgtype="sensor_msgs/msg/Range"
        ),
    )
    mission.run(until=10.0)
    assert trace(tags) == [
        (0.0, "rover", "s1", "start"),
        (7.0, "rover", "s1", "complete"),
        *pair(7.0, "rover", "s2"),
    ]
    assert engine.variables["range"] == 0.7  # the second message found no subscription


def test_publishers_and_service_clients_use_the_bus(tmp_path):
    script = """
        var node = this.environment.variables.ros_node;
        const publisher = node.createPublisher("geometry_msgs/msg/Twist", "cmd_vel");
        publisher.publish({linear: {x: 0.1, y: 0.0, z: 0.0}, angular: {x: 0.0, y: 0.0, z: 0.0}});
        const client = node.createClient("tello_msgs/srv/TelloAction", "tello_action");
        client.waitForService(1000).then((ok) => {
            client.sendRequest({cmd: "takeoff"}, (response) => {
                this.environment.variables.answer = response.rc;
                next();
            });
        });
    """
    mission, tags = build_and_serve(tmp_path, script)
    mission.run(until=5.0)
    assert mission.seen == [
        (
            "/rover/cmd_vel",
            {"linear": {"x": 0.1, "y": 0.0, "z": 0.0}, "angular": {"x": 0.0, "y": 0.0, "z": 0.0}},
        ),
        ("/rover/tello_action/request", {"cmd": "takeoff"}),
        ("/rover/tello_action/response", {"rc": 1}),
    ]
    assert trace(tags) == pair(0.0, "rover", "s1")
    assert mission.engines["rover"].variables["answer"] == 1


def build_and_serve(tmp_path, script):
    """A mission whose bus answers ``tello_action`` requests with ``{"rc": 1}``."""
    from fame_suite import build

    mission, tags = build(model(tmp_path, script))
    mission.seen = []
    bus = mission.bus
    bus.tap(lambda e: mission.seen.append((e.topic, e.data)) if "/rover/" in e.topic else None)
    bus.subscribe(
        "/rover/tello_action/request",
        lambda e: bus.publish("/rover/tello_action/response", {"rc": 1}, msgtype=e.msgtype),
    )
    return mission, tags


def test_a_script_that_throws_ends_the_instance_naming_the_element_and_line(tmp_path):
    script = "var v = this.environment.variables;\nvar n = null;\nv.y = n.x;\nnext();"
    mission, tags = run(model(tmp_path, script, "next();"))
    engine = mission.engines["rover"]
    # the uncaught error ends the instance, so the script task ends without completing
    aborted = [(0.0, "rover", "s1", "start"), (0.0, "rover", "s1", "ate_abort")]
    assert trace(tags, aborts=True) == aborted
    assert engine.failures == [
        "robot rover: error \"script task s1 (S1): TypeError: cannot read property 'x' of "
        'null (line 3)" thrown at s1 (S1) was not caught; the process instance ended'
    ]


def test_next_with_an_error_throws_a_bpmn_error(tmp_path):
    mission, _ = run(model(tmp_path, 'next(new Error("no weed"));'))
    assert mission.engines["rover"].failures == [
        "robot rover: error 'no weed' thrown at s1 (S1) was not caught; the process instance ended"
    ]


def test_an_endless_loop_is_stopped_by_the_time_limit(tmp_path, monkeypatch):
    monkeypatch.setattr(javascript, "TIME_LIMIT", 0.2)
    monkeypatch.setattr(
        javascript.JavaScript.__init__,
        "__kwdefaults__",
        {
            "time_limit": 0.2,
            "memory_limit": javascript.MEMORY_LIMIT,
        },
    )
    mission, _ = run(model(tmp_path, "while (true) {}\nnext();"))
    rover = mission.engines["rover"]
    assert rover.failures == [
        "robot rover: script task s1 (S1) ran longer than its time limit of 0.2 s of CPU time; "
        "the process instance ended (a model error: no boundary event catches it)"
    ]
    assert (rover.completed, rover.failed) == (0, 1)


def test_a_syntax_error_is_refused_when_the_process_is_deployed(tmp_path):
    with pytest.raises(
        ModelError,
        match=r"s1 \(S1\) has a script that cannot run: JavaScript "
        r"syntax error on line 2",
    ):
        run(model(tmp_path, "var a = 1;\nvar = 2;\nnext();"))


def test_no_file_network_or_process_access_exists():
    context = javascript.quickjs.Context()
    context.eval(javascript._PRELUDE)
    assert (
        context.eval("[typeof require, typeof std, typeof os, typeof fetch, typeof process].join()")
        == "undefined,undefined,undefined,undefined,undefined"
    )


def test_values_a_script_sets_reach_python_as_json_would_carry_them(tmp_path):
    """The usual outcome (plain values and next()) travels as flat text, anything else as
    JSON; either way Python gets what JSON.stringify and json.loads make of the values."""
    script = """
        var v = this.environment.variables;
        v.whole = 6; v.negative = -3; v.half = 0.5; v.huge = 1e21; v.small = 1e-7;
        v.not_a_number = NaN; v.yes = true; v.no = false; v.empty = null;
        v.text = "a b"; v.separator = "a\\u001fb"; delete v.gone;
        next();
    """
    mission, _ = run(model(tmp_path, script), variables={"rover": {"gone": 1}})
    got = mission.engines["rover"].variables
    expected = {"whole": 6, "negative": -3, "half": 0.5, "huge": 1e21, "small": 1e-7}
    expected |= {"not_a_number": None, "yes": True, "no": False, "empty": None}
    expected |= {"text": "a b", "separator": "a\x1fb"}
    assert {k: got[k] for k in expected} == expected and "gone" not in got
    assert [type(got[k]) for k in ("whole", "negative", "half", "huge")] == [int, int, float, float]
    # the same values one at a time: each alone takes the flat path unless it cannot
    for name, value in expected.items():
        text = {None: "null", True: "true", False: "false"}.get(value, repr(value))
        if name in ("not_a_number", "separator"):
            text = {"not_a_number": "NaN", "separator": '"a\\u001fb"'}[name]
        one = f"this.environment.variables.{name} = {text}; next();"
        mission, _ = run(model(tmp_path, one))
        assert mission.engines["rover"].variables[name] == value, name


def test_a_script_setting_many_variables_a_long_text_and_a_long_list(tmp_path):
    """Long outboxes come back whole: many plain writes and a long string (flat text), a
    long list of objects (JSON)."""
    plain = """
        var v = this.environment.variables;
        for (var i = 0; i < 2000; i++) { v["value_" + i] = i; }
        v.long = new Array(5001).join("ab");
        next();
    """
    points = """
        var points = [];
        for (var i = 0; i < 2000; i++) { points.push({x: i, y: -i}); }
        this.environment.variables.points = points;
        next();
    """
    mission, _ = run(model(tmp_path, plain, points))
    got = mission.engines["rover"].variables
    assert [got[f"value_{i}"] for i in range(2000)] == list(range(2000))
    assert got["long"] == "ab" * 5000
    assert got["points"] == [{"x": i, "y": -i} for i in range(2000)]
