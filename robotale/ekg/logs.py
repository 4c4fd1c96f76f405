"""The event logs stored in Neo4j: list, show, delete."""

from __future__ import annotations

from typing import Any

from neo4j import Driver

from robotale.ekg.connection import database
from robotale.ekg.queries import cypher, statements
from robotale.errors import InputError


def list_logs(driver: Driver) -> list[dict[str, Any]]:
    """Every stored log as its Log node describes it, by name."""
    records, _, _ = driver.execute_query(cypher("ekg_list_logs"), log=None, database_=database())
    return [record.data() for record in records]


def log_summary(driver: Driver, name: str) -> dict[str, Any]:
    """The Log node's description of ``name`` plus counts taken from the graph.

    ``counts`` maps ``"events"``, ``"entities:robot"``, ``"DF:robot"``,
    ``"DF_C:activity / robot"`` ... to numbers.
    """
    records, _, _ = driver.execute_query(cypher("ekg_list_logs"), log=name, database_=database())
    if not records:
        raise InputError(f"There is no log named {name!r} in Neo4j (see `robotale logs list`).")
    counted, _, _ = driver.execute_query(cypher("ekg_log_counts"), log=name, database_=database())
    counts = {
        r["what"] if r["type"] is None else f"{r['what']}:{r['type']}": r["count"]
        for r in counted
        if r["count"]
    }
    return records[0].data() | {"counts": counts}


def log_exists(driver: Driver, name: str) -> bool:
    """Whether anything (a Log node or events) is stored under ``name``."""
    records, _, _ = driver.execute_query(cypher("ekg_log_exists"), log=name, database_=database())
    return bool(records[0]["exists"])


def delete_log(driver: Driver, name: str) -> None:
    """Remove a log and everything that belongs to it (nothing happens if there is none)."""
    with driver.session(database=database()) as session:
        for statement in statements("ekg_delete_log"):
            session.run(statement, log=name).consume()


def graph_counts(driver: Driver) -> dict[str, int]:
    """``{"node:Event": n, "relationship:DF": m, ...}`` for the whole database."""
    with driver.session(database=database()) as session:
        result = session.run(cypher("ekg_graph_counts"))
        return {f"{r['kind']}:{r['name']}": r["count"] for r in result if r["count"]}
