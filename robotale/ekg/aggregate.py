"""Aggregate a stored log into a Class graph: Class nodes, OBSERVED, DF_C and BEGINS edges.

The keys a log is ingested with are aggregated in pandas and written with the events
(:func:`robotale.ekg.tables.class_tables`). This aggregation runs in Neo4j
(``cypher/ekg_aggregate_*.cypher``), so any log already in the database can be aggregated
again by another key, e.g. ``["activity", "robot"]`` (the thesis' "multi-slider": one class
per activity and robot), with the same result.
"""

from __future__ import annotations

from collections.abc import Sequence

from neo4j import Driver

from robotale.ekg.connection import database
from robotale.ekg.logs import log_info
from robotale.ekg.tables import check_name, property_name
from robotale.errors import InputError
from robotale.queries import cypher, statements


def aggregation_key(key: str | Sequence[str]) -> list[str]:
    """``"activity,robot"`` or ``["activity", "robot"]`` as Event property names."""
    names = key.split(",") if isinstance(key, str) else list(key)
    properties = [property_name(name.strip()) for name in names if name.strip()]
    if not properties:
        raise InputError("An aggregation key needs at least one property, e.g. activity.")
    return [check_name(name, "aggregation key") for name in properties]


def class_type(key: Sequence[str]) -> str:
    """The Class ``type`` of a key: its properties joined by ``+`` (``activity+robot``)."""
    return "+".join(key)


def aggregate(driver: Driver, log: str, key: str | Sequence[str]) -> int:
    """(Re)build the classes of ``key`` for the stored log ``log``; returns the DF_C count.

    Raises :class:`LogNotFound` when there is no log of that name and :class:`InputError`
    when its events lack one of the key's properties.
    """
    properties = aggregation_key(key)
    info = log_info(driver, log)
    missing = [p for p in properties if p not in (info["properties"] or [])]
    if missing:
        raise InputError(
            f"The events of log {log!r} have no property {missing[0]!r} to aggregate by; "
            f"they have {', '.join(info['properties'] or [])}."
        )
    return aggregate_unchecked(driver, log, properties)


def aggregate_unchecked(driver: Driver, log: str, key: list[str]) -> int:
    """:func:`aggregate` for a key already checked against the log's properties."""
    kind = create_classes(driver, log, key)
    edges = create_df_c(driver, log, kind)
    driver.execute_query(cypher("ekg_aggregate_begins"), log=log, type=kind, database_=database())
    driver.execute_query(cypher("ekg_log_add_class_type"), log=log, type=kind, database_=database())
    return edges


def ensure_begins(driver: Driver, log: str, kind: str) -> None:
    """Write the BEGINS edges of the classes ``kind`` when the log has none: logs stored by
    earlier versions of robotale computed where entities begin on every reading instead."""
    records, _, _ = driver.execute_query(
        cypher("ekg_has_begins"), log=log, type=kind, database_=database()
    )
    if not records[0]["recorded"]:
        driver.execute_query(
            cypher("ekg_aggregate_begins"), log=log, type=kind, database_=database()
        )


def create_classes(driver: Driver, log: str, key: list[str]) -> str:
    """Class nodes and OBSERVED edges for ``key`` (replacing earlier ones); the class type."""
    kind = class_type(key)
    with driver.session(database=database()) as session:
        for statement in statements("ekg_delete_classes"):
            session.run(statement, log=log, type=kind).consume()
        session.run(cypher("ekg_aggregate_classes"), log=log, type=kind, key=key).consume()
    return kind


def create_df_c(driver: Driver, log: str, kind: str) -> int:
    """DF_C edges between the classes of type ``kind``; how many."""
    records, _, _ = driver.execute_query(
        cypher("ekg_aggregate_df_c"), log=log, type=kind, sources=None, database_=database()
    )
    return int(records[0]["edges"])
