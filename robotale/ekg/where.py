"""The ``where`` filter of an aggregation step: a small expression language, parsed and checked
here and run by Neo4j as a parameterised condition, or on a table of the nodes in pandas
(:mod:`robotale.ekg.where_table`) with Cypher's meaning.

Grammar (keywords in any case)::

    expr    := and ("or" and)*
    and     := not ("and" not)*
    not     := "not" not | "(" expr ")" | test
    test    := name op value | name "in" "[" value ("," value)* "]" | name "is" ["not"] "null"
    op      := "=" | "==" | "!=" | "<>" | "<" | "<=" | ">" | ">="
    value   := number | 'text' | "text" | true | false | datetime("ISO time")
    name    := a property name (letters, digits, _ . :) or any name in `backticks`

The condition handed to Neo4j holds only the operators above, the node's properties by their
validated names (quoted with backticks) and parameters ``$w0``, ``$w1`` ... for the values: a
value never becomes Cypher text.
"""

from __future__ import annotations

import datetime as dt
import re
from collections.abc import Collection
from dataclasses import dataclass, field
from typing import Any, NoReturn

from robotale.errors import InputError
from robotale.eventlog import schema

_TOKEN = re.compile(
    r"""\s*(?:(?P<number>-?\d+(?:\.\d*)?(?:[eE][-+]?\d+)?)
          |(?P<string>'(?:[^'\\]|\\.)*'|"(?:[^"\\]|\\.)*")
          |(?P<quoted>`[^`]+`)
          |(?P<op><=|>=|<>|!=|==|=|<|>)
          |(?P<punct>[()\[\],])
          |(?P<word>[A-Za-z_][A-Za-z0-9_.:]*))""",
    re.VERBOSE,
)
_OPERATORS = {"=": "=", "==": "=", "!=": "<>", "<>": "<>", "<": "<", "<=": "<=", ">": ">",
              ">=": ">="}  # fmt: skip
_KEYWORDS = {"and", "or", "not", "in", "is", "null", "true", "false"}
_TIME_FUNCTIONS = {"datetime", "date"}


@dataclass(frozen=True)
class Condition:
    """A checked ``where``: the Cypher condition on the node ``node`` and its parameters."""

    cypher: str
    parameters: dict[str, Any]
    names: frozenset[str]  # the properties it reads
    #: the same condition as a tree, for evaluating it on a table: ("or"|"and", [parts]),
    #: ("not", part), ("in", name, [values]), ("null"|"not null", name), (op, name, value);
    #: None: always true
    tree: Any = field(default=None, compare=False)


@dataclass(frozen=True)
class _Token:
    kind: str
    text: str
    at: int


def parse_where(text: str, node: str, known: Collection[str], what: str) -> Condition:
    """Parse ``text`` into a condition on the variable ``node``; every property it names must
    be one of ``known``. ``what`` names the filter in messages ("the where of step 2")."""
    parser = _Parser(_tokens(text, what), text, node, what)
    cypher, tree = parser.expression()
    if not parser.done():
        parser.fail("expected and, or or the end")
    unknown = sorted(parser.names - set(known))
    if unknown:
        raise InputError(
            f"{what.capitalize()} names {unknown[0]!r}, which these nodes do not have; "
            f"they have {', '.join(sorted(known)) or 'no properties'}."
        )
    return Condition(cypher, parser.parameters, frozenset(parser.names), tree)


def _tokens(text: str, what: str) -> list[_Token]:
    if not isinstance(text, str) or not text.strip():
        raise InputError(f"{what.capitalize()} is empty: give a condition such as battery < 50.")
    tokens, at = [], 0
    while at < len(text):
        if not text[at:].strip():
            break
        match = _TOKEN.match(text, at)
        if match is None or match.end() == at:
            raise InputError(
                f"{what.capitalize()} cannot be read at character {at + 1}: "
                f"{text[at : at + 20].strip()!r}."
            )
        kind = str(match.lastgroup)
        tokens.append(_Token(kind, match.group(kind), match.start(kind)))
        at = match.end()
    return tokens


class _Parser:
    def __init__(self, tokens: list[_Token], text: str, node: str, what: str) -> None:
        self.tokens, self.text, self.node, self.what = tokens, text, node, what
        self.position = 0
        self.parameters: dict[str, Any] = {}
        self.names: set[str] = set()

    # -- the grammar, one method per rule: each returns the Cypher text and the tree
    def expression(self) -> tuple[str, Any]:
        parts = [self.conjunction()]
        while self.keyword("or"):
            parts.append(self.conjunction())
        return _joined(parts, "OR")

    def conjunction(self) -> tuple[str, Any]:
        parts = [self.negation()]
        while self.keyword("and"):
            parts.append(self.negation())
        return _joined(parts, "AND")

    def negation(self) -> tuple[str, Any]:
        if self.keyword("not"):
            text, tree = self.negation()
            return f"(NOT {text})", ("not", tree)
        if self.punct("("):
            text, tree = self.expression()
            if not self.punct(")"):
                self.fail("expected )")
            return f"({text})", tree
        return self.test()

    def test(self) -> tuple[str, Any]:
        name, prop = self.name()
        if self.keyword("in"):
            values = self.values()
            return f"{name} IN {self.parameter(values)}", ("in", prop, values)
        if self.keyword("is"):
            negated = self.keyword("not")
            if not self.keyword("null"):
                self.fail("expected null")
            tree = ("not null" if negated else "null", prop)
            return f"{name} IS {'NOT ' if negated else ''}NULL", tree
        token = self.next()
        if token is None or token.kind != "op":
            self.fail("expected a comparison (=, <>, <, <=, >, >=), in or is", token)
        op, value = _OPERATORS[token.text], self.value()
        return f"{name} {op} {self.parameter(value)}", (op, prop, value)

    def name(self) -> tuple[str, str]:
        token = self.next()
        if token is None or token.kind not in ("word", "quoted"):
            self.fail("expected a property name", token)
        name = token.text.strip("`") if token.kind == "quoted" else token.text
        if token.kind == "word" and name.lower() in _KEYWORDS:
            self.fail("expected a property name", token)
        if not schema.is_property_name(name):
            self.fail(f"{name!r} is not a property name", token)
        self.names.add(name)
        # Safe to quote: a property name holds no backtick (schema.is_property_name).
        return f"{self.node}.`{name}`", name

    def values(self) -> list[Any]:
        if not self.punct("["):
            self.fail("expected [ after in")
        found = [self.value()]
        while self.punct(","):
            found.append(self.value())
        if not self.punct("]"):
            self.fail("expected , or ]")
        return found

    def value(self) -> Any:
        token = self.next()
        if token is None:
            self.fail("expected a value")
        if token.kind == "number":
            return float(token.text) if re.search(r"[.eE]", token.text) else int(token.text)
        if token.kind == "string":
            return _unquote(token.text)
        word = token.text.lower() if token.kind == "word" else ""
        if word in ("true", "false"):
            return word == "true"
        if word in _TIME_FUNCTIONS and self.punct("("):
            argument = self.next()
            if argument is None or argument.kind != "string" or not self.punct(")"):
                self.fail(f'expected {word}("ISO time")', argument)
            return _time(word, _unquote(argument.text), self)
        self.fail("expected a number, a quoted text, true, false or datetime(...)", token)

    # -- tokens
    def next(self) -> _Token | None:
        if self.position >= len(self.tokens):
            return None
        self.position += 1
        return self.tokens[self.position - 1]

    def keyword(self, word: str) -> bool:
        return self._take(lambda t: t.kind == "word" and t.text.lower() == word)

    def punct(self, mark: str) -> bool:
        return self._take(lambda t: t.kind == "punct" and t.text == mark)

    def _take(self, accept: Any) -> bool:
        if self.position < len(self.tokens) and accept(self.tokens[self.position]):
            self.position += 1
            return True
        return False

    def done(self) -> bool:
        return self.position >= len(self.tokens)

    def parameter(self, value: Any) -> str:
        name = f"w{len(self.parameters)}"
        self.parameters[name] = value
        return f"${name}"

    def fail(self, expected: str, token: _Token | None = None) -> NoReturn:
        if token is None and self.position < len(self.tokens):
            token = self.tokens[self.position]
        where = f"at character {token.at + 1} ({token.text!r})" if token else "at its end"
        raise InputError(f"{self.what.capitalize()} cannot be read {where}: {expected}.")


def _joined(parts: list[tuple[str, Any]], word: str) -> tuple[str, Any]:
    if len(parts) == 1:
        return parts[0]
    text = "(" + f" {word} ".join(p[0] for p in parts) + ")"
    return text, (word.lower(), [p[1] for p in parts])


def _unquote(text: str) -> str:
    return re.sub(r"\\(.)", r"\1", text[1:-1])


def _time(function: str, text: str, parser: _Parser) -> dt.date | dt.datetime:
    try:
        if function == "date":
            return dt.date.fromisoformat(text)
        moment = dt.datetime.fromisoformat(text)
    except ValueError:
        parser.fail(f"{text!r} is not an ISO {'date' if function == 'date' else 'time'}")
    # robotale stores times with their zone; a time without one is read as UTC, since Neo4j
    # never orders a time with a zone against one without.
    return moment if moment.tzinfo else moment.replace(tzinfo=dt.UTC)
