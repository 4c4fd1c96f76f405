"""The event knowledge graph of one stored log, as plain values to compare: what a test sets
against the graph ``robotale ingest`` builds of the same events."""

from __future__ import annotations

from collections import Counter

from robotale.ekg.connection import database


def graph(driver, name: str, case: str | None = None) -> dict:
    """The log's graph without Neo4j's internal ids: events with their properties, and every
    CORR, DF, COMM, OBSERVED, DF_C and BEGINS edge by the ids of its ends. ``case``: the
    log's one case, left out of the event ids and properties (two logs of one run whose case
    is named differently, a live log's and its recording's, compare equal)."""

    def rows(text: str) -> list[dict]:
        records, _, _ = driver.execute_query(text, log=name, database_=database())
        data = [r.data() for r in records]
        return data if case is None else [_without(r, case) for r in data]

    events = rows("MATCH (e:Event {log: $log}) RETURN e.id AS id, properties(e) AS p")
    return {
        "events": {r["id"]: {k: v for k, v in r["p"].items() if k != "log"} for r in events},
        "corr": Counter(
            tuple(r.values())
            for r in rows(
                "MATCH (e:Event {log: $log})-[:CORR]->(n:Entity) RETURN e.id, n.type, n.id"
            )
        ),
        "df": Counter(
            tuple(r.values())
            for r in rows(
                "MATCH (a:Event {log: $log})-[r:DF]->(b) "
                "RETURN a.id, b.id, r.entityType, r.entityId"
            )
        ),
        "comm": Counter(
            tuple(r.values())
            for r in rows("MATCH (a:Event {log: $log})-[r:COMM]->(b) RETURN a.id, b.id, r.msgId")
        ),
        "observed": Counter(
            tuple(r.values())
            for r in rows(
                "MATCH (e:Event {log: $log})-[:OBSERVED]->(c:Class) RETURN e.id, c.type, c.id"
            )
        ),
        "df_c": Counter(
            (r["a"], r["b"], r["t"], r["k"], r["n"], round(r["mean"], 9), round(r["median"], 9))
            for r in rows(
                "MATCH (a:Class {log: $log})-[r:DF_C]->(b) RETURN a.id AS a, b.id AS b, "
                "a.type AS t, r.entityType AS k, r.count AS n, r.meanSeconds AS mean, "
                "r.medianSeconds AS median"
            )
        ),
        "begins": Counter(
            tuple(r.values())
            for r in rows(
                "MATCH (n:Entity {log: $log})-[r:BEGINS]->(c:Class) "
                "RETURN n.type, n.id, c.type, c.id, r.cases"
            )
        ),
        "entities": Counter(
            tuple(r.values()) for r in rows("MATCH (n:Entity {log: $log}) RETURN n.type, n.id")
        ),
    }


def _without(value, case: str):
    """``value`` with the case's name taken out of every text (``run:12`` -> ``:12``)."""
    if isinstance(value, dict):
        return {k: _without(v, case) for k, v in value.items()}
    if isinstance(value, str) and (value == case or value.startswith(f"{case}:")):
        return value[len(case) :]
    return value
