"""Scripts, conditions and ``${...}`` templates, compiled once when a process is deployed.

Python scripts and conditions run with the robot's variables as their local names (an
assignment in a script sets a variable) and ``robot`` (the robot handle) and ``BpmnError`` as
globals. JavaScript ones (FAME's language) run in the embedded engine of
:mod:`robotale.fame_runtime.javascript`; here they are only checked for syntax. Models are
trusted code: a Python script can do anything the Python process can, a JavaScript one only
what FAME's runtime API offers.
"""

from __future__ import annotations

import dis
import json
import re
import textwrap
from collections.abc import Mapping
from dataclasses import dataclass
from functools import lru_cache
from types import CodeType
from typing import Any

from robotale.fame_runtime.javascript import function_source, member_names, syntax_error
from robotale.fame_runtime.model import JAVASCRIPT, PYTHON, XPATH, Expression


class BpmnError(Exception):
    """Raised by a script or a skill to throw a BPMN error event named ``name``."""

    def __init__(self, name: str) -> None:
        super().__init__(name)
        self.name = name


@dataclass(frozen=True, slots=True)
class Compiled:
    """A compiled condition (``eval``) or script (``exec``) and the variable names it reads
    and assigns, which conditional events and data associations need."""

    code: CodeType | None  # None for JavaScript, which its own engine compiles
    source: str  # Python text, or the JavaScript ``function (next) {...}`` source
    reads: frozenset[str]
    writes: frozenset[str]  # JavaScript's are known only when it runs
    language: str = PYTHON


#: what ``language`` / ``scriptFormat`` values robotale evaluates, for the messages
EVALUATED = "python or javascript"


def _javascript(expression: Expression, *, condition: bool) -> Compiled:
    source = function_source(expression.text, condition=condition)
    error = syntax_error(source)
    if error is not None:
        raise ValueError(error)
    return Compiled(None, source, member_names(expression.text), frozenset(), JAVASCRIPT)


def compile_condition(expression: Expression) -> Compiled:
    """A condition as Python ``eval`` code; ValueError explains what cannot be compiled."""
    if expression.language == JAVASCRIPT:
        return _javascript(expression, condition=True)
    if expression.language != PYTHON:
        raise ValueError(
            f"it is in {expression.language!r}, an expression language robotale does not "
            f"evaluate (it evaluates {EVALUATED})"
        )
    text = _unwrap_placeholder(expression.text.strip())
    try:
        return _compile(text, "eval", expression.element_id)
    except ValueError:
        if expression.stated:
            raise
        # no language named anywhere: the standard's default is XPath, not a Python typo
        raise ValueError(
            f"it is no Python or JavaScript, so it is read in {XPATH!r}, the standard's default "
            "expression language when neither the element nor the file names one, which "
            f"robotale does not evaluate (it evaluates {EVALUATED}: give "
            'language="python" or language="javascript")'
        ) from None


def compile_script(expression: Expression) -> Compiled:
    """A script task's body as Python ``exec`` code; ValueError explains what cannot."""
    if expression.language == JAVASCRIPT:
        return _javascript(expression, condition=False)
    if expression.language != PYTHON:
        raise ValueError(
            f"scripts in {expression.language!r} are not supported (robotale runs {EVALUATED})"
        )
    return _compile(textwrap.dedent(expression.text.strip("\n")), "exec", expression.element_id)


def _unwrap_placeholder(text: str) -> str:
    """Camunda writes conditions as ``${expression}``."""
    if text.startswith("${") and text.endswith("}"):
        return text[2:-1].strip()
    return text


def _compile(text: str, mode: str, element_id: str) -> Compiled:
    try:
        code = compile(text or "None", f"<{element_id}>", mode)
    except SyntaxError as error:
        raise ValueError(f"Python syntax error on line {error.lineno}: {error.msg}") from None
    return Compiled(code, text, frozenset(_names(code, _READS)), frozenset(_stores(code)))


_READS = frozenset(("LOAD_NAME", "LOAD_GLOBAL"))


def _names(code: CodeType, opnames: frozenset[str]) -> set[str]:
    names = {i.argval for i in dis.get_instructions(code) if i.opname in opnames}
    for const in code.co_consts:
        if isinstance(const, CodeType):
            names |= _names(const, opnames)
    return names


def _stores(code: CodeType) -> set[str]:
    # Only the top level: names assigned inside comprehensions or functions are their own.
    stores = ("STORE_NAME", "DELETE_NAME")
    return {i.argval for i in dis.get_instructions(code) if i.opname in stores}


# -- ${...} templates --------------------------------------------------------------------------

_PLACEHOLDER = re.compile(r"\$\{([^}]*)\}")


@lru_cache(maxsize=4096)
def _placeholder_code(expression: str) -> CodeType:
    try:
        return compile(expression.strip() or "None", "<${}>", "eval")
    except SyntaxError:
        raise ValueError(f"${{{expression}}} is not a Python expression") from None


def evaluate(expression: str, names: Mapping[str, Any], env: dict[str, Any]) -> Any:
    """The value of the Python expression inside one ``${...}``."""
    return eval(_placeholder_code(expression), env, names)


def self_reference(value: str) -> str | None:
    """``x`` when ``value`` is ``${x}`` (a parameter declared to be set at run time)."""
    match = _PLACEHOLDER.fullmatch(value.strip())
    return match.group(1).strip() if match and match.group(1).strip().isidentifier() else None


def literal(text: str) -> Any:
    """A parameter value as written: JSON when it parses (numbers, booleans, objects), else the
    text itself."""
    try:
        return json.loads(text)
    except ValueError:
        return text


def unset(expression: str, names: Mapping[str, Any], env: Mapping[str, Any]) -> bool:
    """Whether ``expression`` is a bare name that no variable or global has."""
    name = expression.strip()
    return name.isidentifier() and name not in names and name not in env


def substitute(
    text: str, names: Mapping[str, Any], env: dict[str, Any], *, keep_unset: bool = False
) -> Any:
    """A parameter's value: ``${expr}`` alone gives the value itself, ``${...}`` inside text is
    formatted into it, anything else is a literal. With ``keep_unset`` a ``${name}`` of a
    variable nobody set stays as written (FAME's engine assigns data objects' properties as
    written; robotale does so for processes in its JavaScript dialect)."""
    whole = _PLACEHOLDER.fullmatch(text.strip())
    if whole:
        if keep_unset and unset(whole.group(1), names, env):
            return text.strip()
        return evaluate(whole.group(1), names, env)
    if "${" not in text:
        return literal(text)

    def fill(match: re.Match[str]) -> str:
        if keep_unset and unset(match.group(1), names, env):
            return match.group(0)
        return str(evaluate(match.group(1), names, env))

    return _PLACEHOLDER.sub(fill, text)


def render_json(
    template: str, names: Mapping[str, Any], env: dict[str, Any], *, keep_unset: bool = False
) -> Any:
    """A JSON payload template with ``${...}`` filled in: inside a JSON string the value is
    formatted as text, elsewhere it is written as JSON (``{"x": ${x}}`` -> ``{"x": 1.5}``).
    With ``keep_unset`` a ``${name}`` of a variable nobody set is null (JSON's nearest to
    JavaScript's undefined) outside a string and stays as written inside one."""
    out, inside, position = [], False, 0
    while position < len(template):
        char = template[position]
        if template.startswith("${", position):
            end = template.index("}", position)
            expression = template[position + 2 : end]
            if keep_unset and unset(expression, names, env):
                out.append(template[position : end + 1] if inside else "null")
                position = end + 1
                continue
            value = evaluate(expression, names, env)
            out.append(json.dumps(str(value))[1:-1] if inside else json.dumps(value))
            position = end + 1
            continue
        if char == '"' and (position == 0 or template[position - 1] != "\\"):
            inside = not inside
        out.append(char)
        position += 1
    text = "".join(out)
    try:
        return json.loads(text)
    except ValueError:
        return substitute(template, names, env, keep_unset=keep_unset)
