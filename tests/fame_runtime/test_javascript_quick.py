"""Quick JavaScript scripts: a script that names every variable it touches runs on just those
values. Each case runs the same steps twice, quick and on the whole of the variables (the
path every script took before), and the two must leave the same variables, completions,
changes and output."""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any

import pytest
from fame_suite import pair, run, trace
from test_engine_time import SENSED, Stopper
from test_javascript import model

from robotale.fame_runtime import javascript
from robotale.fame_runtime.bus import InProcessBus
from robotale.fame_runtime.clock import EngineCost, SimClock

V = "this.environment.variables."
#: a value only Python has (a skill's object)
HANDLE = object()


@dataclass
class Robot:
    """One JavaScript runtime and what it reported."""

    variables: dict[str, Any]
    runtime: javascript.JavaScript = field(init=False)
    log: list[tuple] = field(default_factory=list)
    quick: int = 0  # scripts run on just the variables they name

    def __post_init__(self) -> None:
        self.runtime = javascript.JavaScript(
            "rover",
            InProcessBus(SimClock()),
            self.variables,
            schedule=lambda work: work(),
            changed=lambda names: self.log.append(("changed", sorted(names))),
            output=lambda line: self.log.append(("output", line)),
        )
        run_quick = self.runtime._run_quick

        def counted(*args: Any) -> Any:
            self.quick += 1
            return run_quick(*args)

        self.runtime._run_quick = counted

    def script(self, text: str) -> None:
        def done(error: str | None, value: Any) -> None:
            self.log.append(("next", error, value))

        try:
            self.runtime.run_script(javascript.function_source(text, condition=False), done)
        except javascript.ScriptFailure as failure:
            self.log.append(("failure", failure.text))
        except javascript.ScriptLimit as limit:
            self.log.append(("limit", limit.what))

    def condition(self, text: str) -> Any:
        return self.runtime.condition(javascript.function_source(text, condition=True))


def both(monkeypatch, steps, variables=None) -> tuple[Robot, Robot]:
    """Run ``steps`` (a script's text, or a function changing the variables as Python
    would) quick, then again with every script on the whole of the variables."""
    robots = []
    for quick in (True, False):
        with monkeypatch.context() as patch:
            if not quick:
                patch.setattr(javascript, "touches", lambda body: None)
            robot = Robot(dict(variables or {}))
            for step in steps:
                robot.script(step) if isinstance(step, str) else step(robot.variables)
                robot.log.append(("step", dict(robot.variables)))
            robots.append(robot)
    return robots[0], robots[1]


def same(a: Any, b: Any) -> bool:
    """Equal, NaN equal to NaN, and of the same types (6 is not 6.0)."""
    if isinstance(a, float) and isinstance(b, float) and math.isnan(a) and math.isnan(b):
        return True
    if isinstance(a, dict) and isinstance(b, dict):
        return a.keys() == b.keys() and all(same(a[k], b[k]) for k in a)
    if isinstance(a, list | tuple) and isinstance(b, list | tuple):
        return len(a) == len(b) and all(same(x, y) for x, y in zip(a, b, strict=True))
    return type(a) is type(b) and a == b


def by_step(log: list[tuple]) -> list[list[tuple]]:
    """What each step reported, in a fixed order, then the variables after it."""
    steps: list[list[tuple]] = [[]]
    for entry in log:
        if entry[0] == "step":
            steps[-1].sort(key=repr)
            steps[-1].append(entry)
            steps.append([])
        else:
            steps[-1].append(entry)
    return steps


CASES = {
    "numbers keep JSON's int and float": [
        f"{V}a = 3 * 2; next();",
        f"{V}b = 12 * 0.5; {V}c = 0.5; {V}d = 1e21; {V}e = 1e20; {V}f = -0; next();",
        f"{V}g = {V}a / 4; next();",
    ],
    "strings, booleans, null, NaN and the separator": [
        f'{V}s = "a b"; {V}t = true; {V}u = false; {V}n = null; next();',
        f'{V}x = NaN; {V}sep = "a\\u001fb"; {V}inf = Infinity; next();',
    ],
    "compound assignments, ++ and --": [
        f"{V}i = 1; next();",
        f"{V}i += 4; {V}i *= 3; {V}i++; --{V}i; {V}j = {V}i ** 2; {V}k ??= 7; next();",
        f"{V}i <<= 2; {V}i >>>= 1; {V}flag = {V}i >= 30; next();",
    ],
    "destructuring, for-in and comments as targets": [
        f"[{V}p, {V}q] = [1, 2]; next();",
        f"({{x: {V}r}} = {{x: 5}}); for ({V}key in {{m: 1}}) {{}} next();",
        f"{V}w /* a comment */ = 9; {V}w // another\n  += 1; next();",
    ],
    "a variable set to undefined is gone": [
        f"{V}gone = 1; next();",
        f"{V}gone = undefined; next();",
        f"next(null, typeof {V}gone);",
        f"{V}gone = 2; next();",
        f'console.log("going"); {V}gone = undefined; next();',
        f"next(null, typeof {V}gone);",
    ],
    "what Python changed between two calls is seen": [
        f"{V}n = 1; next();",
        lambda v: v.update(n=10, m="from python"),
        f'{V}n = {V}n + 1; {V}text = {V}m + "!"; next();',
        lambda v: v.pop("m"),
        f"next(null, {V}m === undefined && {V}n === 11);",
    ],
    "integers beyond 32 bits and beyond a double": [
        lambda v: v.update(big=2**40, bigger=2**60, negative=-(2**33)),
        f"{V}b1 = {V}big + 1; {V}b2 = {V}negative * 2; next();",
        f"{V}b3 = {V}bigger; next();",
    ],
    "one variable set and next called, with a value or not": [
        f"{V}a = 1; next(null, 2);",
        f"{V}a = 2; next(null);",
        f"{V}a = true; next();",
        f'{V}a = "text"; next();',
        f"{V}a = 2 ** 31; next();",
        f"{V}a = 0.1 + 0.2; next();",
        f"{V}a = 12 * 0.5; next();",
        f"{V}a = 2; next('failed');",
    ],
    "a list, an object or a value only Python has runs on the whole": [
        lambda v: v.update(points=[1, 2, 3], pose={"x": 1}, handle=HANDLE),
        f"{V}count = {V}points.length; {V}x = {V}pose.x; next();",
        f"{V}seen = typeof {V}handle; next();",
        f"{V}sum = {V}count + {V}x; next();",
    ],
    "objects and arrays set by a quick script": [
        f"{V}o = {{x: [1, 2, {{y: null}}]}}; {V}z = 1; next();",
        f"{V}copy = {V}o.x.length; next();",
    ],
    "console.log, next with a value, next with an error": [
        f'console.log("at", {V}a, {{k: 1}}); {V}a = 2; next(null, "v");',
        'next(new Error("no weed"));',
        f"{V}after = 1; next(); next(new Error('ignored'));",
    ],
    "a script that throws after writing": [
        f"{V}before = 1;\nvar n = null;\n{V}after = n.x;\nnext();",
        f"next(null, {V}before);",
    ],
    "next not called, then a task that reads what it wrote": [
        f"{V}pending = 1;",
        f"{V}read = {V}pending + 1; next();",
    ],
    "quick and whole-variables scripts in turn": [
        f"{V}a = 1; next();",
        "var v = this.environment.variables; v.b = v.a + 1; v.a = 5; next();",
        f"{V}c = {V}a + {V}b; next();",
        "var v = this.environment.variables; delete v.c; v.list = [v.a]; next();",
        f"{V}d = {V}c === undefined ? {V}a : -1; next();",
    ],
    "an assignment not made leaves Python's value, one made is reported even if equal": [
        lambda v: v.update(f=2.0, z=-0.0, same=3),
        f"if ({V}f > 5) {{ {V}f = 1; {V}z = 1; }} {V}same = 3; next();",
        f"if ({V}f < 5) {{ {V}f = {V}f; }} next();",
    ],
    "a variable only read, one maybe assigned but unchanged": [
        lambda v: v.update(x=3),
        f"Math.max({V}x, 1); [{V}x][0]; next(null, {V}x > 1);",
    ],
}


@pytest.mark.parametrize("steps", CASES.values(), ids=CASES.keys())
def test_quick_scripts_do_what_scripts_on_the_whole_of_the_variables_do(monkeypatch, steps):
    quick, whole = both(monkeypatch, steps)
    assert same(quick.variables, whole.variables), (quick.variables, whole.variables)
    # within a step, the order of a completion and a change does not matter to the engine
    assert same(by_step(quick.log), by_step(whole.log)), (quick.log, whole.log)
    assert len(quick.log) > len(steps)  # something was reported
    assert quick.quick > 0 and whole.quick == 0


def test_the_cases_run_quick_where_they_can(monkeypatch):
    """The differential test above means something only if the quick path is taken: every
    script but those that keep the variables object or read a list, an object, a value only
    Python has or an integer a double cannot hold (six)."""
    scripts = [step for steps in CASES.values() for step in steps if isinstance(step, str)]
    quick = sum(both(monkeypatch, steps)[0].quick for steps in CASES.values())
    assert quick == len(scripts) - 6


def test_values_reach_python_as_json_would_carry_them(monkeypatch):
    quick, _ = both(monkeypatch, CASES["numbers keep JSON's int and float"])
    got = quick.variables
    assert (got["a"], got["b"], got["c"], got["e"], got["f"], got["g"]) == (
        6,
        6,
        0.5,
        10**20,
        0,
        1.5,
    )
    assert [type(got[k]) for k in "abcdefg"] == [int, int, float, float, int, int, float]
    quick, _ = both(monkeypatch, CASES["integers beyond 32 bits and beyond a double"])
    assert quick.variables["b1"] == 2**40 + 1 and quick.variables["b2"] == -(2**34)
    # 2**60 as a double, written as JSON writes it (shortest digits): Python reads an int
    assert quick.variables["b3"] == 1152921504606847000


@pytest.mark.parametrize(
    ("body", "names"),
    [
        (f"{V}value_3 = 3 * 2; next();", ("value_3",)),
        ("next(null, environment.variables.a > environment.variables.b);", ("a", "b")),
        (f"{V}a++; --{V}b; {V}c >>>= 1; {V}d ??= 1; {V}a == 1; {V}f <= 2;", "abcdf"),
        (f"[{V}a, {V}b] = x; for ({V}c of y) {{}} {V}d /* */ = 1; f({V}e);", "abcde"),
        (f"if ({V}x) {{ next(); }} else {{ next(null, {V}y.length); }}", ("x", "y")),
        ("while (true) {}\nnext();", ()),
    ],
)
def test_touches_names_each_variable_once_in_order(body, names):
    assert javascript.touches(body) == tuple(names)


@pytest.mark.parametrize(
    "body",
    [
        "var v = this.environment.variables; v.x = 1; next();",
        "this.environment.variables[name] = 1; next();",
        "Object.keys(this.environment.variables).length; next();",
        "f(environment.variables); next();",
        "var e = environment; e.variables.x = 1; next();",
        "this.environment.output.x = 1; next();",
        f"setTimeout(() => {{ {V}x = 1; next(); }});",
        f"var cb = function () {{ {V}x = 1; }}; next();",
        f"var o = {{ f() {{ {V}x = 1; }} }}; next();",
        f"Promise.resolve().then(next); {V}x = 1;",
        "later = next;",
        f"delete {V}x; next();",
        f"eval('{V}x = 1'); next();",
        f"{V}node.createPublisher('t', 'x'); next();",
        f"{V}toString; next();",
        "".join(f"{V}v{i} = {i}; " for i in range(javascript.QUICK_NAMES + 1)),
    ],
)
def test_touches_refuses_what_could_reach_the_variables_otherwise(body):
    assert javascript.touches(body) is None


def test_a_quick_script_stopped_by_its_time_limit_leaves_nothing_behind():
    robot = Robot({})
    robot.runtime.time_limit = 0.2
    robot.runtime.context.set_time_limit(0.2)
    robot.script("next(null, 1); while (true) {}")
    robot.script(f"{V}x = 1;")  # never calls next: must not complete with the 1 above
    assert robot.log == [
        ("limit", "ran longer than its time limit of 0.2 s of CPU time"),
        ("changed", ["x"]),
    ]


def test_a_javascript_function_kept_in_a_variable_keeps_later_scripts_whole():
    robot = Robot({})
    robot.script("this.environment.variables.f = Math.max; next();")
    robot.script(f"{V}m = {V}f(2, 7); next();")
    assert robot.variables["m"] == 7  # Python never held f: JavaScript's value was used


def test_a_gateway_condition_reads_what_quick_scripts_wrote(tmp_path):
    scripts = [f"{V}x = 1; next();", *[f"{V}x++; next();"] * 4]
    mission, tags = run(model(tmp_path, *scripts, condition=f"{V}x === 5"))
    assert mission.engines["rover"].variables["x"] == 5
    assert trace(tags)[-2:] == pair(0.0, "rover", "yes")


@pytest.mark.parametrize(
    "script",
    [f"{V}command = 0.0; next();", "var v = environment.variables; v.command = 0; next();"],
)
def test_a_javascript_script_cost_delays_the_command_it_computes(models, tmp_path, script):
    """The stopper of test_engine_time with its script in JavaScript, quick or not: the
    script's cost passes on the clock before the command goes out."""
    text = (models / "stopper.bpmn").read_text()
    text = text.replace('scriptFormat="python"', 'scriptFormat="javascript"')
    path = tmp_path / "stopper.bpmn"
    path.write_text(
        text.replace(
            "<bpmn:script>command = 0.0</bpmn:script>", f"<bpmn:script>{script}</bpmn:script>"
        )
    )
    stopper = Stopper(path, EngineCost(script=0.025))
    stopper.reading(SENSED, 0.3)
    assert stopper.run().sent == [pytest.approx(SENSED + 0.025, abs=1e-12)]
    assert stopper.engine.variables["command"] == 0
