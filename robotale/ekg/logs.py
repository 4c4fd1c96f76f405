"""The event logs stored in Neo4j: list, show, delete."""

from __future__ import annotations

from neo4j import Driver

from robotale.ekg.connection import database
from robotale.ekg.queries import statements


def delete_log(driver: Driver, name: str) -> None:
    """Remove a log and everything that belongs to it (nothing happens if there is none)."""
    with driver.session(database=database()) as session:
        for statement in statements("ekg_delete_log"):
            session.run(statement, log=name).consume()


def graph_counts(driver: Driver) -> dict[str, int]:
    """``{"node:Event": n, "relationship:DF": m, ...}`` for the whole database."""
    with driver.session(database=database()) as session:
        result = session.run(statements("ekg_graph_counts")[0])
        return {f"{r['kind']}:{r['name']}": r["count"] for r in result if r["count"]}
