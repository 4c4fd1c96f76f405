"""Event Knowledge Graph in Neo4j: the connection, the schema, loading, and aggregation into
Class graphs (the local server robotale starts is :mod:`robotale.neo4j_server`). Every query
is a file in ``cypher/``.

``build_ekg(driver, log, name, ...)`` stores a canonical event log; ``connect()`` returns a
driver for the configured server; ``aggregate(driver, name, key)`` (re)builds a Class graph;
``run_spec(driver, name, read_spec(path))`` runs an aggregation specification, ``undo`` takes
steps back and ``level_graph`` reads a level (docs/aggregate.md).
"""

import importlib
from typing import Any

_EXPORTS = {
    "build_ekg": "robotale.ekg.build",
    "BuildSummary": "robotale.ekg.build",
    "connect": "robotale.ekg.connection",
    "aggregate": "robotale.ekg.aggregate",
    "read_spec": "robotale.ekg.spec",
    "parse_spec": "robotale.ekg.spec",
    "run_spec": "robotale.ekg.steps",
    "undo": "robotale.ekg.steps",
    "level_graph": "robotale.ekg.steps",
    "delete_log": "robotale.ekg.logs",
    "list_logs": "robotale.ekg.logs",
    "log_summary": "robotale.ekg.logs",
}
__all__ = sorted(_EXPORTS)


def __getattr__(name: str) -> Any:
    # Imported on first use, so `robotale neo4j status` does not load pandas (half a second).
    if name in _EXPORTS:
        return getattr(importlib.import_module(_EXPORTS[name]), name)
    raise AttributeError(f"module 'robotale.ekg' has no attribute {name!r}")
