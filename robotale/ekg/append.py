"""Append runs to a stored log without rebuilding it: :func:`append_ekg`.

The appended runs are new cases, and neither DF nor COMM crosses a case, so their events,
CORR, DF, COMM and OBSERVED edges are written as a build writes them; entity and class nodes
the log already has are found rather than created again, BEGINS edges add their cases, and
the DF_C edges leaving the classes the new runs reach are computed again from the DF edges
of those classes (an exact median needs every duration). Everything is written in one
transaction: a failed or interrupted append leaves the log exactly as it was.
"""

from __future__ import annotations

import dataclasses
import time
from collections.abc import Callable, Sequence
from typing import Any

import numpy as np
import pandas as pd
from neo4j import Driver, ManagedTransaction
from neo4j.exceptions import DriverError, Neo4jError

from robotale.ekg.build import (
    BuildSummary,
    check_key_sizes,
    check_keys,
    check_log_name,
    summarise,
    unique_keys,
    why,
    write_graph,
)
from robotale.ekg.columnar import log_build, widened_schema
from robotale.ekg.connection import database
from robotale.ekg.interrupt import DeferredInterrupt
from robotale.ekg.load import Loader
from robotale.ekg.logs import log_info, log_values
from robotale.ekg.tables import (
    SUMMARY_PROPERTIES,
    ClassTables,
    GraphTables,
    class_tables,
    entity_types,
    graph_tables,
    property_name,
)
from robotale.ekg.tables import log_values as table_values
from robotale.ekg.writelock import log_write_lock
from robotale.errors import InputError, ServerError
from robotale.eventlog import schema
from robotale.queries import cypher


class _Interrupted(Exception):
    """Ctrl-C inside the transaction: an Exception, so the driver rolls the transaction back."""


def append_ekg(
    driver: Driver,
    log: pd.DataFrame,
    name: str,
    entities: Sequence[str] | None = None,
    aggregate: Sequence[str | Sequence[str]] | None = None,
) -> BuildSummary:
    """Append the runs of ``log`` (a canonical event log) to the stored log ``name``.

    ``entities`` and ``aggregate`` default to the stored log's; given, they must be the
    same. A column the log does not have yet becomes a new event property: the new events
    carry it, the Log node lists it and its columnar copy gains the column (empty for the
    events stored before). Refused (nothing written) when there is no complete log ``name``,
    when the runs lack a column the log has, or when one of their cases or event ids is
    already in the log.
    """
    started = time.perf_counter()
    check_log_name(name)
    with log_write_lock(driver, name, "appending"):
        info = complete_log_info(driver, name)
        added = _new_columns(log, info["properties"] or [], name)
        types = _same_entities(log, entities, info["entityTypes"] or [], name)
        keys = same_keys(aggregate, info["classTypes"] or [], name)
        tables = graph_tables(log, types, first=int(info["events"]))
        check_keys(tables.events, keys)
        check_key_sizes(tables, keys)
        stored = log_values(driver, name)
        _check_new_cases(tables.events, stored["case"], name)
        check_new_event_ids(driver, tables.events, name)
        classes = [class_tables(tables, key) for key in keys]
        summary: dict[str, Any] = {"events": int(info["events"]) + len(tables.events)}
        summary |= merged_values(stored, table_values(tables.events))
        if added:
            summary |= widened_properties(driver, name, log, info["properties"] or [], added)
        _write_or_keep(driver, name, tables, classes, summary)
    result = summarise(name, tables, classes)
    return dataclasses.replace(result, seconds=time.perf_counter() - started)


def complete_log_info(driver: Driver, name: str) -> dict[str, Any]:
    """What the Log node of ``name`` records; refused unless the log is complete."""
    info = log_info(driver, name)
    if info["status"] != "complete":
        raise InputError(
            f"The log {name!r} is {info['status']}, not complete: only a complete log can be "
            "appended to."
        )
    return info


def _new_columns(log: pd.DataFrame, stored: Sequence[str], name: str) -> list[str]:
    """The columns of ``log`` (as given) that the stored log does not have yet; refused if
    ``log`` lacks one it has."""
    # Every event gets an id and a msg_role, whether the log has such columns or not.
    given = {property_name(c) for c in log.columns} | {"id", schema.MSG_ROLE}
    missing = sorted(set(stored) - given)
    if missing:
        raise InputError(
            f"The runs to append have no column {missing[0]!r}, which the log {name!r} has: "
            "appended runs need every column of the log."
        )
    return [c for c in log.columns if property_name(c) not in set(stored)]


def widened_properties(
    driver: Driver, name: str, log: pd.DataFrame, stored: Sequence[str], added: list[str]
) -> dict[str, Any]:
    """What the Log node records of its event properties once ``added`` (columns of
    ``log``) join them: the list, and the columnar copy's column types if it has them."""
    summary: dict[str, Any] = {"properties": [*stored, *map(property_name, added)]}
    types = log_build(driver, name).columns
    if types is not None:
        summary["columns"] = widened_schema(types, log[added])
    return summary


def _same_entities(
    log: pd.DataFrame, entities: Sequence[str] | None, stored: list[str], name: str
) -> list[str]:
    if entities is None:
        return stored
    given = entity_types([property_name(c) for c in log.columns], entities)
    if set(given) != set(stored):
        raise InputError(
            f"The log {name!r} has the entity types {', '.join(stored) or 'none'}, not "
            f"{', '.join(given)}: leave out --entities to append with the log's own."
        )
    return stored


def same_keys(
    aggregate: Sequence[str | Sequence[str]] | None, stored: list[str], name: str
) -> list[list[str]]:
    keys = [kind.split("+") for kind in stored]
    if aggregate is None:
        return keys
    given = ["+".join(key) for key in unique_keys(aggregate)]
    if set(given) != set(stored):
        raise InputError(
            f"The log {name!r} has the class types {', '.join(stored) or 'none'}, not "
            f"{', '.join(given)}: leave out --aggregate to append with the log's own."
        )
    return keys


def _check_new_cases(events: pd.DataFrame, stored: Sequence[Any], name: str) -> None:
    known = {str(case) for case in stored}
    repeated = [case for case in events["case"].astype(str).unique() if case in known]
    if repeated:
        raise InputError(
            f"The case {repeated[0]!r} is already in the log {name!r}: each run is appended "
            "once (give the new run another case id)."
        )


def check_new_event_ids(driver: Driver, events: pd.DataFrame, name: str) -> None:
    records, _, _ = driver.execute_query(
        cypher("ekg_find_event_ids"), ids=events["id"].tolist(), log=name, database_=database()
    )
    if records:
        raise InputError(
            f"The event id {records[0]['id']!r} is already in the log {name!r}: event ids must "
            "be unique in the whole log."
        )


def merged_values(stored: dict[str, Any], new: dict[str, list[str]]) -> dict[str, list[str]]:
    return {
        key: sorted({str(v) for v in stored[column] if v is not None} | set(new[key]))
        for key, column in SUMMARY_PROPERTIES.items()
    }


def _write_or_keep(
    driver: Driver,
    name: str,
    tables: GraphTables,
    classes: list[ClassTables],
    summary: dict[str, Any],
) -> None:
    write_transaction(driver, name, _append, name, tables, classes, summary)


def write_transaction(driver: Driver, name: str, work: Callable[..., None], *args: Any) -> None:
    """Run ``work(tx, *args, between_batches)`` as one managed transaction appending to the
    log ``name``; on any failure Neo4j rolls it back, and Ctrl-C waits for the next batch."""
    try:
        with (
            DeferredInterrupt() as interrupt,
            driver.session(database=database()) as session,
        ):
            session.execute_write(work, *args, _checked(interrupt.check))
    except _Interrupted:
        raise KeyboardInterrupt from None
    except (Neo4jError, DriverError, OSError) as error:
        raise ServerError(
            f"Appending to the log {name!r} failed ({why(error)}); the log is as it was."
        ) from error


def _checked(check: Callable[[], None]) -> Callable[[], None]:
    def between_batches() -> None:
        try:
            check()
        except KeyboardInterrupt:
            raise _Interrupted from None

    return between_batches


def _append(
    tx: ManagedTransaction,
    name: str,
    tables: GraphTables,
    classes: list[ClassTables],
    summary: dict[str, Any],
    between_batches: Callable[[], None],
) -> None:
    loader = Loader(None, name, None, between_batches, tx=tx)
    class_nodes = write_graph(loader, tables, classes, new_log=False)
    for kind, nodes in zip(classes, class_nodes, strict=True):
        between_batches()
        sources = np.unique(nodes[kind.df_c["source"].to_numpy()]).tolist()
        parameters = {"log": name, "type": kind.type, "sources": sources}
        tx.run(cypher("ekg_delete_df_c"), parameters).consume()
        tx.run(cypher("ekg_aggregate_df_c"), parameters).consume()
    tx.run(cypher("ekg_log_summary"), log=name, summary=summary).consume()
