"""The Cypher console's work: run a user's query so that it can only read, and show the rows.

Every statement runs in a transaction opened in Neo4j's READ access mode, so the server itself
refuses anything that would write (nodes, relationships, indexes, ``IN TRANSACTIONS`` batches):
nothing the console runs can change the graph. Values come in as parameters, never pasted into
the text. The examples are the analyst's questions among the files of ``cypher/``.
"""

from __future__ import annotations

import re
from collections.abc import Mapping
from dataclasses import dataclass
from importlib.resources import files
from typing import Any

import neo4j
from neo4j import Driver, unit_of_work
from neo4j.exceptions import ClientError
from neo4j.graph import Node, Path, Relationship

from robotale.ekg.connection import database
from robotale.ekg.queries import split_statements
from robotale.errors import InputError

_PARAMETER = re.compile(r"\$([A-Za-z_][A-Za-z0-9_]*)")
_ACCESS_MODE = "Neo.ClientError.Statement.AccessMode"


class WriteRefused(InputError):
    """The query would change the graph, and the console only reads."""


@dataclass(frozen=True)
class StatementResult:
    statement: str
    columns: list[str]
    rows: list[list[Any]]
    #: rows the query returned; more than ``len(rows)`` when the console's limit cut them
    total: int

    def to_dict(self) -> dict[str, Any]:
        return {
            "statement": self.statement,
            "columns": self.columns,
            "rows": self.rows,
            "total": self.total,
        }


@dataclass(frozen=True)
class Example:
    name: str
    description: str
    text: str
    parameters: list[str]


def run_read_only(
    driver: Driver,
    text: str,
    parameters: Mapping[str, Any] | None = None,
    row_limit: int = 1000,
    timeout: float = 30.0,
) -> list[StatementResult]:
    """Run each statement of ``text`` (separated by ``;``) in its own read transaction.

    Raises :class:`WriteRefused` when one would write and :class:`InputError` when Neo4j
    rejects one (syntax, a missing parameter ...).
    """
    statements = split_statements(text)
    if not statements:
        raise InputError("Type a Cypher query (or pick an example) to run.")
    work = unit_of_work(timeout=timeout)(_read)
    results = []
    with driver.session(database=database(), default_access_mode=neo4j.READ_ACCESS) as session:
        for statement in statements:
            try:
                results.append(
                    session.execute_read(work, statement, dict(parameters or {}), row_limit)
                )
            except ClientError as error:
                raise _explain(error) from None
    return results


def _read(tx: neo4j.ManagedTransaction, statement: str, parameters: dict, limit: int):
    result = tx.run(statement, parameters)
    columns = list(result.keys())
    rows, total = [], 0
    for record in result:
        total += 1
        if total <= limit:
            rows.append([cell(value) for value in record.values()])
    return StatementResult(statement, columns, rows, total)


def _explain(error: ClientError) -> InputError:
    if error.code == _ACCESS_MODE:
        return WriteRefused(
            "The console only reads, and this query would change the graph; run writes "
            "with robotale's commands or in Neo4j Browser."
        )
    message = (error.message or str(error)).strip().splitlines()[0]
    return InputError(f"Neo4j could not run the query: {message}")


def cell(value: Any) -> Any:
    """A result value as JSON: graph elements as Neo4j Browser writes them, times as ISO text."""
    if isinstance(value, Node):
        labels = "".join(f":{label}" for label in sorted(value.labels))
        return f"({labels} {_properties(value)})"
    if isinstance(value, Relationship):
        return f"[:{value.type} {_properties(value)}]"
    if isinstance(value, Path):
        return [cell(element) for element in _path_elements(value)]
    if isinstance(value, list | tuple) and not hasattr(value, "srid"):
        return [cell(item) for item in value]
    if isinstance(value, dict):
        return {str(key): cell(item) for key, item in value.items()}
    if value is None or isinstance(value, bool | int | float | str):
        return value
    if hasattr(value, "iso_format"):
        return value.iso_format()
    return str(value)


def _properties(entity: Node | Relationship) -> str:
    shown = ", ".join(f"{key}: {_literal(cell(value))}" for key, value in sorted(entity.items()))
    return "{" + shown + "}"


def _literal(value: Any) -> str:
    return repr(value) if isinstance(value, str) else str(value)


def _path_elements(path: Path) -> list[Node | Relationship]:
    elements: list[Node | Relationship] = [path.start_node]
    for relationship in path.relationships:
        elements += [relationship, relationship.end_node]
    return elements


#: the files of ``cypher/`` that ask an analyst's questions of an EKG; robotale's own queries
#: (which build and read the graph) stay there but are not offered as examples
EXAMPLE_PREFIX = "ask_"


def examples() -> list[Example]:
    """The analyst's queries of ``cypher/``, each with its leading comment as description."""
    found = []
    for resource in sorted(files("robotale.cypher").iterdir(), key=lambda r: r.name):
        if not (resource.name.startswith(EXAMPLE_PREFIX) and resource.name.endswith(".cypher")):
            continue
        text = resource.read_text(encoding="utf-8")
        comment = []
        for line in text.splitlines():
            if not line.lstrip().startswith("//"):
                break
            comment.append(line.lstrip()[2:].strip())
        found.append(
            Example(
                name=resource.name.removesuffix(".cypher"),
                description=" ".join(comment),
                text=text,
                parameters=sorted(set(_PARAMETER.findall(text))),
            )
        )
    return found
