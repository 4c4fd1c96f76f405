"""Conditions, scripts and ${...} templates, including the thesis' JavaScript forms."""

import pytest

from robotale.fame_runtime.expressions import (
    compile_condition,
    compile_script,
    js_condition,
    js_script,
    render_json,
    substitute,
)
from robotale.fame_runtime.model import Expression


@pytest.mark.parametrize(
    ("javascript", "python"),
    [
        # The conditions of the authors' own models.
        (
            "next(null, this.environment.variables.closest_tractor != null);",
            "closest_tractor != None",
        ),
        ("next(null,!this.environment.variables.reached);", "(not reached)"),
        ("next(null,this.environment.variables.map_points.length <= 0);", "len(map_points) <= 0"),
        ("next(null, this.environment.variables.sara == 0);", "sara == 0"),
        ("next(null, !(a && b) || c === 'x');", "(not (a and b)) or c == 'x'"),
        # Listing 5.5 of the thesis.
        ("next(null, variable_2 > 10);", "variable_2 > 10"),
    ],
)
def test_thesis_javascript_conditions_become_python(javascript, python):
    assert js_condition(javascript) == python


def test_javascript_conditions_evaluate_like_javascript():
    code = compile_condition(Expression("next(null, !(x > 1) || y === true);", "javascript", "f"))
    assert eval(code.code, {}, {"x": 0, "y": False}) is True
    assert eval(code.code, {}, {"x": 5, "y": False}) is False
    assert code.reads == {"x", "y"}


def test_javascript_beyond_plain_comparisons_is_refused():
    with pytest.raises(ValueError, match="cannot translate"):
        js_condition(
            "next(null, this.environment.variables.tractor === "
            "this.environment.variables.node.namespace().replace('/', ''));"
        )
    with pytest.raises(ValueError, match="not an assignment"):
        js_script("var node = this.environment.variables.ros_node;\nnext();")


def test_javascript_assignment_scripts_become_python():
    # data.bpmn's "Set Value" script task of the authors' tests.
    text = (
        "this.environment.variables.variable_name = 5;\n"
        "this.environment.variables.loop = 0;\nnext();"
    )
    assert js_script(text) == "variable_name = 5\nloop = 0"
    assert js_script("next();") == ""


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
