"""The console's verdict on a query, made on Neo4j's own reading of it: the plan ``EXPLAIN``
returns (which runs nothing).

Neo4j writes each operator's expressions in the plan as it resolved them: comments gone,
unicode escapes and backticks undone, subqueries, ``CALL { ... }`` and the bodies of
``COLLECT``/``EXISTS``/``COUNT`` as operators of their own. So no spelling of the text changes
what is checked here:

- every operator must work on robotale's database and be a reading one (no ``LOAD CSV``, no
  administration, no writes, no ``IN TRANSACTIONS``);
- every procedure must be one of :data:`ALLOWED_PROCEDURES`;
- every function of a namespace (``duration.between``, ``apoc.version``) must be one of
  Neo4j's built-in functions (as the server lists them) or of :data:`ALLOWED_FUNCTIONS`.
  Functions without a namespace are Neo4j's own: a plugin may not define one (Neo4j refuses
  to load a function "in the root namespace").
"""

from __future__ import annotations

import re
from collections.abc import Iterable, Mapping
from typing import Any

from robotale.errors import InputError
from robotale.neo4j_server.server_config import ALLOWED_FUNCTIONS

#: procedures the console may call: they describe the graph and the server, and change nothing
ALLOWED_PROCEDURES = frozenset(
    {
        "db.labels",
        "db.relationshipTypes",
        "db.propertyKeys",
        "db.schema.visualization",
        "db.schema.nodeTypeProperties",
        "db.schema.relTypeProperties",
        "dbms.components",
        "dbms.showCurrentUser",
    }
)

ONLY_READS = "The console only reads the graph"

#: operators (their names before ``@database``) that do more than read one database
_WRITING = (
    "Create",
    "Merge",
    "Delete",
    "DetachDelete",
    "Set",
    "Remove",
    "Foreach",
    "LockingMerge",
    "EmptyResult",
)
_ADMINISTRATION = ("Show", "Terminate", "Administration", "System", "Alter", "Grant", "Deny")

#: one piece of an operator's details as Neo4j writes them
_TOKEN = re.compile(
    r"""(?P<string>"(?:\\.|[^"\\])*"|'(?:\\.|[^'\\])*')
      | (?P<quoted>`(?:``|[^`])*`)
      | (?P<name>[^\W\d]\w*)
      | (?P<space>\s+)
      | (?P<other>\$\w+|\d[\w.]*|.)""",
    re.VERBOSE | re.DOTALL,
)


class QueryRefused(InputError):
    """The console does not run this query (it would do more than read the graph)."""


class WriteRefused(QueryRefused):
    """The query would change the graph."""


def check_plan(plan: Mapping[str, Any], database: str, built_in: Iterable[str]) -> None:
    """Raise :class:`QueryRefused` when any operator of ``plan`` (``EXPLAIN``'s, as the driver
    returns it) would do more than read ``database`` with the allowed procedures and
    functions; ``built_in`` are the names of Neo4j's built-in functions."""
    allowed = {name.lower() for name in built_in} | {name.lower() for name in ALLOWED_FUNCTIONS}
    for operator, details in operators(plan):
        _check_operator(operator, database)
        calls = dotted_calls(details)
        if operator.partition("@")[0] == "ProcedureCall" and calls:
            _check_procedure(calls.pop(0))
        for function in calls:
            if function.lower() not in allowed:
                raise QueryRefused(
                    f"{ONLY_READS}: the function {function} is not one of Neo4j's own, and a "
                    "plugin's functions are refused."
                )


def operators(plan: Mapping[str, Any]) -> list[tuple[str, str]]:
    """Every operator of ``plan`` as (its type, its details)."""
    found = [(str(plan.get("operatorType", "")), str(plan.get("args", {}).get("Details", "")))]
    for child in plan.get("children", []):
        found += operators(child)
    return found


def _check_operator(operator: str, database: str) -> None:
    name, _, where = operator.partition("@")
    if where and where != database:
        raise QueryRefused(f"{ONLY_READS} of robotale's database ({database}).")
    if name == "LoadCSV":
        raise QueryRefused(f"{ONLY_READS}: LOAD CSV (reading files and URLs) is refused.")
    if name.startswith(_ADMINISTRATION):
        raise QueryRefused(f"{ONLY_READS}: administration commands are refused.")
    if name.startswith("Transaction"):
        raise WriteRefused(f"{ONLY_READS}: CALL {{ ... }} IN TRANSACTIONS is refused.")
    if name.startswith(_WRITING):
        raise WriteRefused(
            "The console only reads, and this query would change the graph; run writes "
            "with robotale's commands or in Neo4j Browser."
        )


def _check_procedure(procedure: str) -> None:
    if procedure not in ALLOWED_PROCEDURES:
        allowed = ", ".join(sorted(ALLOWED_PROCEDURES))
        raise QueryRefused(
            f"{ONLY_READS}: the procedure {procedure} is not one it calls ({allowed})."
        )


def dotted_calls(details: str) -> list[str]:
    """The names with a namespace called in ``details`` (``apoc.text.repeat(``), in order.

    A label in an index seek (``n:Event(log)``) has no namespace: a dot inside backticks
    belongs to one name (Neo4j reads such a call as a function of no namespace, and has none)."""
    tokens = _tokens(details)
    calls = []
    for start, (kind, text) in enumerate(tokens):
        if kind != "name" or (start and tokens[start - 1] == ("other", ".")):
            continue
        parts, end = [text], start
        while (
            end + 2 < len(tokens)
            and tokens[end + 1] == ("other", ".")
            and tokens[end + 2][0] == "name"
        ):
            parts.append(tokens[end + 2][1])
            end += 2
        if len(parts) > 1 and end + 1 < len(tokens) and tokens[end + 1] == ("other", "("):
            calls.append(".".join(parts))
    return calls


def _tokens(details: str) -> list[tuple[str, str]]:
    # (kind, text): quoted names count as names, without their backticks
    found = []
    for match in _TOKEN.finditer(details):
        kind, text = str(match.lastgroup), match.group()
        if kind == "space":
            continue
        if kind == "quoted":
            kind, text = "name", text[1:-1].replace("``", "`")
        found.append((kind, text))
    return found
