"""Conditions, scripts and ${...} templates, including the thesis' JavaScript forms."""

import pytest

from robotale.fame_runtime.expressions import (
    compile_condition,
    compile_script,
    render_json,
    substitute,
)
from robotale.fame_runtime.javascript import JavaScript
from robotale.fame_runtime.model import Expression


def javascript_value(text: str, variables: dict) -> object:
    """What a JavaScript condition passes to ``next`` with these variables."""
    compiled = compile_condition(Expression(text, "javascript", "f"))
    runtime = JavaScript(
        "drone", None, dict(variables), schedule=None, changed=lambda _: None, output=print
    )
    return runtime.condition(compiled.source)


@pytest.mark.parametrize(
    ("javascript", "variables", "value"),
    [
        # The conditions of the authors' own models.
        (
            "next(null, this.environment.variables.closest_tractor != null);",
            {"closest_tractor": "tractor_1"},
            True,
        ),
        ("next(null, this.environment.variables.closest_tractor != null);", {}, False),
        ("next(null,!this.environment.variables.reached);", {"reached": False}, True),
        ("next(null,this.environment.variables.map_points.length <= 0);", {"map_points": []}, True),
        ("next(null, this.environment.variables.sara == 0);", {"sara": 0}, True),
        ("next(null, !(a && b) || c === 'x');", {}, "reference"),
        # Listing 5.5 of the thesis: a bare name is a global, not a variable, in JavaScript.
        ("next(null, this.environment.variables.variable_2 > 10);", {"variable_2": 11}, True),
    ],
)
def test_thesis_javascript_conditions_evaluate_in_the_engine(javascript, variables, value):
    if value == "reference":  # undeclared globals throw in JavaScript, as in FAME
        with pytest.raises(Exception, match="ReferenceError: a is not defined"):
            javascript_value(javascript, variables)
        return
    assert javascript_value(javascript, variables) is value


def test_javascript_conditions_evaluate_like_javascript():
    text = "next(null, !(environment.variables.x > 1) || environment.variables.y === true);"
    assert javascript_value(text, {"x": 0, "y": False}) is True
    assert javascript_value(text, {"x": 5, "y": False}) is False
    assert {"x", "y"} <= compile_condition(Expression(text, "javascript", "f")).reads


def test_the_javascript_the_translator_refused_now_compiles():
    compile_condition(
        Expression(
            "next(null, this.environment.variables.tractor === "
            "this.environment.variables.node.namespace().replace('/', ''));",
            "javascript",
            "f",
        )
    )
    compile_script(
        Expression("var node = this.environment.variables.ros_node;\nnext();", "javascript", "s")
    )
    with pytest.raises(ValueError, match="JavaScript syntax error on line 2"):
        compile_script(Expression("var a = 1;\nvar = 2;", "javascript", "s"))


def test_python_scripts_report_what_they_assign_and_conditions_what_they_read():
    script = compile_script(
        Expression(
            "    import math\n    d = math.hypot(x - x0, y)\n    near = d < limit\n", "python", "s"
        )
    )
    assert script.writes == {"math", "d", "near"}
    condition = compile_condition(
        Expression("${battery < low and all(v > 0 for v in cells)}", "python", "f")
    )
    assert condition.reads == {"battery", "low", "all", "cells"}
    with pytest.raises(ValueError, match="Python syntax error on line 1"):
        compile_script(Expression("x = = 1", "python", "s"))
    with pytest.raises(ValueError, match="scripts in 'groovy' are not supported"):
        compile_script(Expression("x = 1", "groovy", "s"))


def test_templates_fill_values_as_json_outside_strings_and_as_text_inside():
    names = {"x": 1.5, "name": 'tr"1', "tags": ["a"]}
    assert render_json('{"x": ${x}, "n": "${name}", "l": ${tags}}', names, {}) == {
        "x": 1.5,
        "n": 'tr"1',
        "l": ["a"],
    }
    assert render_json("${name}", names, {}) == 'tr"1'
    assert render_json("true", {}, {}) is True
    assert substitute("${x * 2}", names, {}) == 3.0
    assert substitute("at ${x} m", names, {}) == "at 1.5 m"
    assert substitute("50", {}, {}) == 50 and substitute("paperino", {}, {}) == "paperino"


def test_an_unset_name_stays_as_written_only_in_fames_dialect():
    # FAME's engine assigns data object properties as written and leaves unset payload
    # values undefined: robotale keeps the text, and writes null where JSON needs a value
    names = {"x": 1.5}
    assert substitute("${tractor_name}", names, {}, keep_unset=True) == "${tractor_name}"
    assert substitute("at ${y} m", names, {}, keep_unset=True) == "at ${y} m"
    assert substitute("${x}", names, {}, keep_unset=True) == 1.5
    assert render_json('{"x": ${x}, "y": ${y}, "n": "${n}"}', names, {}, keep_unset=True) == {
        "x": 1.5,
        "y": None,
        "n": "${n}",
    }
    assert substitute("${len([x])}", names, {"len": len}, keep_unset=True) == 1
    with pytest.raises(NameError):  # robotale's own (Python) dialect still names the mistake
        substitute("${tractor_name}", names, {})
    with pytest.raises(NameError):
        render_json('{"y": ${y}}', names, {})
