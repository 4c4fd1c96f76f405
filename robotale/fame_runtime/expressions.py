"""Scripts, conditions and ``${...}`` templates, compiled once when a process is deployed.

Scripts and conditions are Python. They run with the robot's variables as their local names
(an assignment in a script sets a variable) and ``robot`` (the robot handle) and
``BpmnError`` as globals. Models are trusted code, exactly like FAME's JavaScript: a model can
do anything the Python process can.

The thesis' JavaScript is accepted in its two plain forms, translated to Python here:
conditions ``next(null, <comparison>)`` over ``this.environment.variables.<name>``, literals,
``.length``, ``! && || === !==``; and scripts made only of
``this.environment.variables.<name> = <expression>;`` statements and ``next();``. Anything
else in JavaScript is refused when the process is deployed.
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

from robotale.fame_runtime.model import JAVASCRIPT, PYTHON, Expression


class BpmnError(Exception):
    """Raised by a script or a skill to throw a BPMN error event named ``name``."""

    def __init__(self, name: str) -> None:
        super().__init__(name)
        self.name = name


@dataclass(frozen=True, slots=True)
class Compiled:
    """A compiled condition (``eval``) or script (``exec``) and the variable names it reads
    and assigns, which conditional events and data associations need."""

    code: CodeType
    source: str  # the Python text, after translation from JavaScript
    reads: frozenset[str]
    writes: frozenset[str]


def compile_condition(expression: Expression) -> Compiled:
    """A condition as Python ``eval`` code; ValueError explains what cannot be compiled."""
    text = expression.text.strip()
    if expression.language == JAVASCRIPT:
        text = js_condition(text)
    elif expression.language != PYTHON:
        raise ValueError(f"conditions in {expression.language} are not supported")
    text = _unwrap_placeholder(text)
    return _compile(text, "eval", expression.element_id)


def compile_script(expression: Expression) -> Compiled:
    """A script task's body as Python ``exec`` code; ValueError explains what cannot."""
    if expression.language == JAVASCRIPT:
        text = js_script(expression.text)
    elif expression.language == PYTHON:
        text = textwrap.dedent(expression.text.strip("\n"))
    else:
        raise ValueError(f"scripts in {expression.language!r} are not supported (use python)")
    return _compile(text, "exec", expression.element_id)


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


# -- the thesis' JavaScript --------------------------------------------------------------------

_NEXT = re.compile(r"next\s*\(\s*null\s*,(?P<expr>.*)\)\s*;?", re.DOTALL)
_TOKEN = re.compile(
    r"""\s*(?:
        (?P<num>\d+(?:\.\d*)?(?:[eE][+-]?\d+)?|\.\d+)
      | (?P<str>"(?:[^"\\]|\\.)*"|'(?:[^'\\]|\\.)*')
      | (?P<name>[A-Za-z_$][\w$]*(?:\s*\.\s*[A-Za-z_$][\w$]*)*)
      | (?P<op>===|!==|==|!=|<=|>=|&&|\|\||[-+*/%<>!(),])
    )""",
    re.VERBOSE,
)
_VARIABLE_PREFIXES = ("this.environment.variables.", "environment.variables.")
_JS_WORDS = {"null": "None", "undefined": "None", "true": "True", "false": "False"}
_JS_OPS = {"===": "==", "!==": "!=", "&&": "and", "||": "or"}


def js_condition(text: str) -> str:
    """``next(null, <expr>)`` (or a bare JavaScript expression) as a Python expression."""
    match = _NEXT.fullmatch(text.strip())
    return js_expression(match.group("expr") if match else text)


def js_script(text: str) -> str:
    """A JavaScript script of variable assignments and ``next()`` as Python statements."""
    lines = []
    for statement in re.split(r"[;\n]", re.sub(r"//[^\n]*", "", text)):
        statement = statement.strip()
        if not statement or re.fullmatch(r"next\s*\(\s*(null)?\s*\)", statement):
            continue
        target, equals, value = statement.partition("=")
        name = _variable(target.strip())
        if not equals or value.startswith("=") or name is None:
            raise ValueError(
                f"the JavaScript statement {statement!r} is not an assignment to "
                "this.environment.variables.<name>; write the script in Python"
            )
        lines.append(f"{name} = {js_expression(value)}")
    return "\n".join(lines)


def _variable(dotted: str) -> str | None:
    compact = re.sub(r"\s+", "", dotted)
    for prefix in _VARIABLE_PREFIXES:
        if compact.startswith(prefix) and compact[len(prefix) :].isidentifier():
            return compact[len(prefix) :]
    return None


def js_expression(text: str) -> str:
    """A plain JavaScript expression (comparisons, ``!``, ``&&``, ``||``, arithmetic,
    variables, literals, ``.length``) as Python; ValueError for anything else."""
    return _js_tokens(_tokens(text))


def _tokens(text: str) -> list[tuple[str, str]]:
    tokens, position, text = [], 0, text.strip().rstrip(";")
    while position < len(text):
        match = _TOKEN.match(text, position)
        if not match or match.end() == position:
            raise ValueError(
                f"cannot translate the JavaScript {text!r} (at {text[position:]!r}); only "
                "variables, literals, comparisons and ! && || are translated: write it in Python"
            )
        kind = match.lastgroup or ""
        tokens.append((kind, match.group(kind)))
        position = match.end()
        while position < len(text) and text[position].isspace():
            position += 1
    return tokens


def _js_term(tokens: list[tuple[str, str]], position: int) -> tuple[str, int]:
    kind, value = tokens[position]
    if kind == "op" and value == "!":
        operand, position = _js_operand(tokens, position + 1)
        return f"(not {operand})", position
    if kind == "name":
        if position + 1 < len(tokens) and tokens[position + 1] == ("op", "("):
            raise ValueError(
                f"cannot translate the JavaScript call {value}(...): write it in Python"
            )
        return _js_name(value), position + 1
    if kind == "op":
        return _JS_OPS.get(value, value), position + 1
    return value, position + 1


def _js_operand(tokens: list[tuple[str, str]], position: int) -> tuple[str, int]:
    if position >= len(tokens):
        raise ValueError("a JavaScript '!' has nothing to negate")
    if tokens[position] != ("op", "("):
        return _js_term(tokens, position)
    depth, pieces = 0, []
    while position < len(tokens):
        kind, value = tokens[position]
        depth += (value == "(") - (value == ")") if kind == "op" else 0
        if depth == 0:
            inner = _js_tokens(pieces[1:])
            return f"({inner})", position + 1
        pieces.append(tokens[position])
        position += 1
    raise ValueError("unbalanced parentheses in a JavaScript condition")


def _js_tokens(tokens: list[tuple[str, str]]) -> str:
    out, position = [], 0
    while position < len(tokens):
        piece, position = _js_term(tokens, position)
        out.append(piece)
    return " ".join(out)


def _js_name(dotted: str) -> str:
    compact = re.sub(r"\s+", "", dotted)
    if compact in _JS_WORDS:
        return _JS_WORDS[compact]
    for prefix in _VARIABLE_PREFIXES:
        compact = compact.removeprefix(prefix)
    length = compact.endswith(".length")
    compact = compact.removesuffix(".length")
    if not compact.isidentifier():
        raise ValueError(f"cannot translate the JavaScript name {dotted!r}")
    return f"len({compact})" if length else compact


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


def substitute(text: str, names: Mapping[str, Any], env: dict[str, Any]) -> Any:
    """A parameter's value: ``${expr}`` alone gives the value itself, ``${...}`` inside text is
    formatted into it, anything else is a literal."""
    whole = _PLACEHOLDER.fullmatch(text.strip())
    if whole:
        return evaluate(whole.group(1), names, env)
    if "${" not in text:
        return literal(text)
    return _PLACEHOLDER.sub(lambda m: str(evaluate(m.group(1), names, env)), text)


def render_json(template: str, names: Mapping[str, Any], env: dict[str, Any]) -> Any:
    """A JSON payload template with ``${...}`` filled in: inside a JSON string the value is
    formatted as text, elsewhere it is written as JSON (``{"x": ${x}}`` -> ``{"x": 1.5}``)."""
    out, inside, position = [], False, 0
    while position < len(template):
        char = template[position]
        if template.startswith("${", position):
            end = template.index("}", position)
            value = evaluate(template[position + 2 : end], names, env)
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
        return substitute(template, names, env)
