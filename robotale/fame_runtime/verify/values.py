"""What the verifier knows of a robot's variables: plain assignments tracked, the rest unknown.

A script is never run here. Its text is read for writes the verifier can follow:

- a plain assignment at the script's top level (``reached = false`` in JavaScript through
  ``this.environment.variables`` or an alias of it, ``reached = False`` in Python) sets the
  variable to that value in the same synchronous step;
- an assignment inside a callback (a JavaScript ``function``/``=>`` body, a Python ``def`` or
  ``lambda``) happens later, whenever the robot waits: the variable becomes unknown at every
  wait from then on;
- any other write (inside an ``if``, a loop, ``+=``, a value the verifier cannot compute)
  makes the variable unknown at once.

Data objects and parameters are followed the same way: a literal or ``${expression}`` the
verifier can compute sets the variable, anything else makes it unknown.

A condition is computed from the tracked values when it uses only literals, variables,
``not``/``!``, ``and``/``&&``, ``or``/``||``, comparisons and arithmetic; anything else, or an
unknown variable, is :data:`UNKNOWN`, and the explorer then follows both outcomes.
"""

from __future__ import annotations

import ast
import json
import re
import textwrap
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from functools import lru_cache
from typing import Any

from robotale.fame_runtime.model import JAVASCRIPT


class _Unknown:
    """A value the verifier cannot compute (both outcomes of a test on it are explored)."""

    _instance: _Unknown | None = None

    def __new__(cls) -> _Unknown:
        if cls._instance is None:
            cls._instance = super().__new__(cls)
        return cls._instance

    def __repr__(self) -> str:
        return "UNKNOWN"


UNKNOWN: Any = _Unknown()


@dataclass(frozen=True, slots=True)
class Effect:
    """What one script does to the variables the verifier tracks."""

    sets: tuple[tuple[str, ast.expr], ...] = ()  # in order; each value computed when run
    havoc: frozenset[str] = frozenset()  # unknown at once
    later: frozenset[str] = frozenset()  # written by callbacks: unknown at every wait
    waits: bool = False  # completes later (JavaScript ``next()`` only inside a callback)
    unreadable: bool = False  # the verifier cannot read it: every variable may have changed


# -- conditions ----------------------------------------------------------------------------------

_ENV = re.compile(r"\b(?:this\s*\.\s*)?environment\s*\.\s*variables\s*\.\s*([A-Za-z_$][\w$]*)")
_NEXT = re.compile(r"^\s*next\s*\(\s*null\s*,(?P<value>.*)\)\s*;?\s*$", re.DOTALL)
_JS_WORDS = {"true": "True", "false": "False", "null": "None", "undefined": "None"}


def _python_text_of_javascript(text: str, aliases: frozenset[str] = frozenset()) -> str:
    """A JavaScript expression in Python's syntax, as far as the verifier reads it."""
    text = _ENV.sub(r"\1", text.strip().rstrip(";"))
    for alias in aliases:
        text = re.sub(rf"\b{re.escape(alias)}\s*\.\s*([A-Za-z_$][\w$]*)", r"\1", text)
    text = text.replace("===", "==").replace("!==", "!=").replace("&&", " and ")
    text = text.replace("||", " or ")
    text = re.sub(r"!(?!=)", " not ", text)
    text = re.sub(r"\b(true|false|null|undefined)\b", lambda m: _JS_WORDS[m.group(1)], text)
    return text.strip()


@lru_cache(maxsize=4096)
def condition_tree(text: str, language: str) -> ast.expr | None:
    """The expression a condition computes, or None when the verifier cannot read it."""
    if language == JAVASCRIPT:
        body = text.strip()
        wrapped = _NEXT.match(body)
        body = wrapped.group("value") if wrapped else body
        body = _python_text_of_javascript(body)
    else:
        body = text.strip()
    try:
        return ast.parse(body.strip(), mode="eval").body
    except SyntaxError:
        return None


@lru_cache(maxsize=4096)
def condition_names(text: str, language: str) -> tuple[str, ...]:
    """The variables a condition reads, sorted."""
    tree = condition_tree(text, language)
    if tree is None:
        return ()
    return tuple(sorted({n.id for n in ast.walk(tree) if isinstance(n, ast.Name)}))


def evaluate(tree: ast.expr | None, variables: Mapping[str, Any]) -> Any:
    """The value of ``tree`` over the tracked variables, or :data:`UNKNOWN`."""
    if tree is None:
        return UNKNOWN
    try:
        return _value(tree, variables)
    except Exception:  # an operation that fails on these values: the engine would say so
        return UNKNOWN


def truth(value: Any) -> bool | Any:
    """True, False or UNKNOWN."""
    return UNKNOWN if value is UNKNOWN else bool(value)


def _value(node: ast.expr, variables: Mapping[str, Any]) -> Any:
    if isinstance(node, ast.Constant):
        return node.value
    if isinstance(node, ast.Name):
        return variables.get(node.id, UNKNOWN)
    if isinstance(node, ast.UnaryOp):
        operand = _value(node.operand, variables)
        if operand is UNKNOWN:
            return UNKNOWN
        return _UNARY[type(node.op)](operand)
    if isinstance(node, ast.BoolOp):
        return _bool_op(node, variables)
    if isinstance(node, ast.Compare):
        left = _value(node.left, variables)
        result: Any = True
        for op, right_node in zip(node.ops, node.comparators, strict=True):
            right = _value(right_node, variables)
            if left is UNKNOWN or right is UNKNOWN:
                return UNKNOWN
            if not _COMPARE[type(op)](left, right):
                result = False
            left = right
        return result
    if isinstance(node, ast.BinOp):
        left, right = _value(node.left, variables), _value(node.right, variables)
        if left is UNKNOWN or right is UNKNOWN:
            return UNKNOWN
        return _BINARY[type(node.op)](left, right)
    return UNKNOWN


def _bool_op(node: ast.BoolOp, variables: Mapping[str, Any]) -> Any:
    """Three-valued ``and``/``or``: a known deciding operand decides despite unknown ones."""
    deciding = isinstance(node.op, ast.Or)  # the truth value that ends the evaluation
    unknown = False
    last: Any = None
    for operand in node.values:
        last = _value(operand, variables)
        if last is UNKNOWN:
            unknown = True
        elif bool(last) is deciding:
            return last
    return UNKNOWN if unknown else last


_UNARY: dict[type[ast.unaryop], Callable[[Any], Any]] = {
    ast.Not: lambda v: not v,
    ast.USub: lambda v: -v,
    ast.UAdd: lambda v: +v,
}
_COMPARE: dict[type[ast.cmpop], Callable[[Any, Any], Any]] = {
    ast.Eq: lambda a, b: a == b,
    ast.NotEq: lambda a, b: a != b,
    ast.Lt: lambda a, b: a < b,
    ast.LtE: lambda a, b: a <= b,
    ast.Gt: lambda a, b: a > b,
    ast.GtE: lambda a, b: a >= b,
    ast.Is: lambda a, b: a is b,
    ast.IsNot: lambda a, b: a is not b,
    ast.In: lambda a, b: a in b,
    ast.NotIn: lambda a, b: a not in b,
}
_BINARY: dict[type[ast.operator], Callable[[Any, Any], Any]] = {
    ast.Add: lambda a, b: a + b,
    ast.Sub: lambda a, b: a - b,
    ast.Mult: lambda a, b: a * b,
    ast.Div: lambda a, b: a / b,
    ast.Mod: lambda a, b: a % b,
}


# -- scripts -------------------------------------------------------------------------------------


@lru_cache(maxsize=1024)
def script_effect(text: str, language: str) -> Effect:
    """What a script does to the tracked variables (see the module's docstring)."""
    if language == JAVASCRIPT:
        return _javascript_effect(text)
    return _python_effect(text)


def _python_effect(text: str) -> Effect:
    try:
        tree = ast.parse(textwrap.dedent(text))
    except SyntaxError:
        return Effect(unreadable=True)
    sets: list[tuple[str, ast.expr]] = []
    havoc: set[str] = set()
    later: set[str] = set()
    for statement in tree.body:
        if (
            isinstance(statement, ast.Assign)
            and len(statement.targets) == 1
            and isinstance(statement.targets[0], ast.Name)
        ):
            sets.append((statement.targets[0].id, statement.value))
            continue
        for node in ast.walk(statement):
            callback = isinstance(node, ast.FunctionDef | ast.AsyncFunctionDef | ast.Lambda)
            for name in _assigned_names(node):
                (later if callback else havoc).add(name)
    return Effect(tuple(sets), frozenset(havoc), frozenset(later))


def _assigned_names(node: ast.AST) -> set[str]:
    """Names a statement (or a function) assigns, at any depth."""
    found = set()
    for inner in ast.walk(node):
        if isinstance(inner, ast.Name) and isinstance(inner.ctx, ast.Store):
            found.add(inner.id)
    return found


_ALIAS = re.compile(
    r"\b(?:const|let|var)\s+([A-Za-z_$][\w$]*)\s*=\s*(?:this\s*\.\s*)?environment\s*\.\s*"
    r"variables\s*;"
)
_FUNCTION_HEAD = re.compile(r"(=>\s*|\bfunction\b[^{;]*\))\s*$")
_STATEMENT_END = re.compile(r"[;\n]")


def _javascript_effect(text: str) -> Effect:
    """Writes of a FAME script through ``this.environment.variables`` (or an alias of it),
    sorted by where they are: top level, a callback, or another block."""
    aliases = frozenset(_ALIAS.findall(text))
    owners = [r"(?:this\s*\.\s*)?environment\s*\.\s*variables"] + [re.escape(a) for a in aliases]
    write = re.compile(
        rf"\b(?:{'|'.join(owners)})\s*\.\s*([A-Za-z_$][\w$]*)\s*(=(?!=)|\+=|-=|\*=|/=|\+\+|--)"
    )
    sets: list[tuple[str, ast.expr]] = []
    havoc: set[str] = set()
    later: set[str] = set()
    frames = _frames(text)
    for match in write.finditer(text):
        name, operator = match.group(1), match.group(2)
        where = frames[match.start()]
        if where == "callback":
            later.add(name)
            continue
        if where == "top" and operator == "=":
            end = _STATEMENT_END.search(text, match.end())
            value_text = text[match.end() : end.start() if end else len(text)]
            tree = condition_tree(_python_text_of_javascript(value_text, aliases), "python")
            if tree is not None:
                sets.append((name, tree))
                continue
        havoc.add(name)
    calls = [frames[m.start()] for m in re.finditer(r"\bnext\s*\(", text)]
    waits = bool(calls) and "top" not in calls and "block" not in calls
    return Effect(tuple(sets), frozenset(havoc), frozenset(later), waits)


def _frames(text: str) -> list[str]:
    """For each character of a script: ``top`` (its top level), ``callback`` (inside a
    function body) or ``block`` (inside another block: if, for ...)."""
    where = []
    stack: list[str] = []
    for index, char in enumerate(text):
        if char == "{":
            head = text[max(0, index - 200) : index]
            inside_function = "callback" in stack or _FUNCTION_HEAD.search(head) is not None
            stack.append("callback" if inside_function else "block")
        elif char == "}" and stack:
            stack.pop()
        where.append(_kind(stack))
    return where


def _kind(stack: list[str]) -> str:
    if not stack:
        return "top"
    return "callback" if "callback" in stack else "block"


# -- data objects and parameters -----------------------------------------------------------------

_PLACEHOLDER = re.compile(r"\$\{(.*)\}", re.DOTALL)


def parameter_value(template: object, variables: Mapping[str, Any]) -> Any:
    """A data object's or a parameter's value as the engine computes it (``${expr}`` alone:
    the expression's value; a literal: JSON or the text), or :data:`UNKNOWN`."""
    if not isinstance(template, str):
        return UNKNOWN
    whole = _PLACEHOLDER.fullmatch(template.strip())
    if whole:
        return evaluate(condition_tree(whole.group(1), "python"), variables)
    if "${" in template:
        return UNKNOWN  # text with a value formatted in: not a value a condition tests
    try:
        return json.loads(template)
    except ValueError:
        return template
