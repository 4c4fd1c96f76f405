"""Append an object-centric log (OCEL 2.0 or OCED-style CSV) to a stored one:
:func:`append_objects`.

An object-centric log is one case, so its new events continue the DF chains of the stored
objects they relate to. The new events, their CORR and OBSERVED edges and the DF edges among
them are written as :func:`robotale.ekg.append.append_ekg` writes appended runs; then every
object the new events relate to gets its DF chain (and, per class type, its BEGINS edges)
computed again over its stored and new events, and every DF_C edge is computed again from
the DF edges. Objects are merged by id: an object the log has keeps its node and gets the
attributes the new file gives it; object-to-object relations and attribute changes the log
already holds are not written twice. One transaction: a refused or failed append leaves the
log as it was.
"""

from __future__ import annotations

import dataclasses
import time
from collections.abc import Sequence
from typing import Any

import pandas as pd
from neo4j import Driver, ManagedTransaction

from robotale.ekg.append import (
    check_new_event_ids,
    complete_log_info,
    merged_values,
    same_keys,
    widened_properties,
    write_transaction,
)
from robotale.ekg.build import (
    BuildSummary,
    check_key_sizes,
    check_keys,
    check_log_name,
    summarise,
    write_graph,
)
from robotale.ekg.connection import database
from robotale.ekg.load import Loader
from robotale.ekg.logs import log_values
from robotale.ekg.objects import change_parameters, relation_parameters, write_objects
from robotale.ekg.tables import (
    ClassTables,
    GraphTables,
    class_tables,
    graph_tables,
    property_name,
)
from robotale.ekg.tables import log_values as table_values
from robotale.ekg.writelock import log_write_lock
from robotale.errors import InputError
from robotale.eventlog import schema
from robotale.eventlog.objects import Objects
from robotale.queries import cypher


def append_objects(
    driver: Driver,
    log: pd.DataFrame,
    name: str,
    objects: Objects,
    aggregate: Sequence[str | Sequence[str]] | None = None,
) -> BuildSummary:
    """Append the events of the object-centric ``log`` and its ``objects`` to the stored
    log ``name``. Refused (nothing written) when there is no complete log ``name``, when an
    object type is one the log lacks, when an event id is already in it, or when an object id
    is stored with another type. An event attribute the log lacks joins its attributes."""
    started = time.perf_counter()
    check_log_name(name)
    with log_write_lock(driver, name, "appending"):
        info = complete_log_info(driver, name)
        types = _known_types(objects, info["entityTypes"] or [], name)
        added = _new_attributes(log, info["properties"] or [])
        keys = same_keys(aggregate, info["classTypes"] or [], name)
        tables = graph_tables(log, types, first=int(info["events"]))
        check_keys(tables.events, keys)
        check_key_sizes(tables, keys)
        check_new_event_ids(driver, tables.events, name)
        _check_same_types(driver, name, objects, types)
        classes = [class_tables(tables, key) for key in keys]
        summary: dict[str, Any] = {"events": int(info["events"]) + len(tables.events)}
        summary |= merged_values(log_values(driver, name), table_values(tables.events))
        if added:  # the stored events lack it, as they lack the attributes of other types
            summary |= widened_properties(driver, name, log, info["properties"] or [], added)
        new = _without_stored(driver, name, objects, types)
        write_transaction(driver, name, _append, name, tables, classes, new, types, summary)
    result = summarise(name, tables, classes)
    return dataclasses.replace(result, seconds=time.perf_counter() - started)


def _known_types(objects: Objects, stored: list[str], name: str) -> list[str]:
    # A new entity type would need its own column on every stored event and its own DF_C
    # edges: the stored log would no longer be the log one ingest of both files gives.
    given = [property_name(t) for t in objects.entity_types]
    for kind in given:
        if kind not in stored:
            raise InputError(
                f"The object type {kind!r} is not an entity type of the log {name!r} (it has "
                f"{', '.join(stored) or 'none'}): an append adds objects of the log's own types."
            )
    return [kind for kind in stored if kind in given]


def _check_same_types(driver: Driver, name: str, objects: Objects, types: list[str]) -> None:
    table = _typed(objects, types)
    records, _, _ = driver.execute_query(
        cypher("ekg_ocel_other_types"),
        ids=table.index.astype(str).tolist(),
        types=table.tolist(),
        entityTypes=types,
        log=name,
        database_=database(),
    )
    if records:
        found = records[0]
        raise InputError(
            f"The object {found['id']!r} is of type {found['given']!r}, but the log {name!r} "
            f"holds it as {found['stored']!r}: an object keeps its type in the whole log."
        )


def _typed(objects: Objects, types: list[str]) -> pd.Series:
    """Each object's entity type, by object id, for the objects of ``types``."""
    kinds = objects.objects.assign(type=objects.objects["type"].map(objects.column))
    return kinds[kinds["type"].isin(types)].set_index("id")["type"]


def _new_attributes(log: pd.DataFrame, stored: Sequence[str]) -> list[str]:
    """The columns of ``log`` (as given) whose event attribute the stored log lacks. Events of
    an object-centric log carry the attributes of their own type: the new events may lack
    some of the log's attributes and bring others, as one ingest of both files would."""
    own = {"id", schema.MSG_ROLE}  # every event gets these, whatever the file holds
    return [c for c in log.columns if property_name(c) not in {*stored, *own}]


def _without_stored(driver: Driver, name: str, objects: Objects, types: list[str]) -> Objects:
    """``objects`` without the object-to-object relations and attribute changes the log
    already holds (a file split off a log repeats those of the objects it shares)."""
    kinds = _typed(objects, types)
    o2o = objects.o2o[
        objects.o2o["source"].isin(kinds.index) & objects.o2o["target"].isin(kinds.index)
    ]
    o2o = o2o.reset_index(drop=True)
    changes = objects.changes[objects.changes["object"].isin(kinds.index)].reset_index(drop=True)
    return dataclasses.replace(
        objects,
        o2o=_drop_stored(
            driver, name, "ekg_ocel_stored_relations", o2o, relation_parameters(o2o, kinds)
        ),
        changes=_drop_stored(
            driver, name, "ekg_ocel_stored_changes", changes, change_parameters(changes, kinds)
        ),
    )


def _drop_stored(
    driver: Driver, name: str, query: str, table: pd.DataFrame, parameters: dict[str, list[Any]]
) -> pd.DataFrame:
    if table.empty:
        return table
    records, _, _ = driver.execute_query(cypher(query), parameters, log=name, database_=database())
    stored = {int(record["i"]) for record in records}
    return table[~table.index.isin(stored)]


def _append(
    tx: ManagedTransaction,
    name: str,
    tables: GraphTables,
    classes: list[ClassTables],
    objects: Objects,
    types: list[str],
    summary: dict[str, Any],
    between_batches: Any,
) -> None:
    loader = Loader(None, name, None, between_batches, tx=tx)
    write_graph(loader, tables, classes, new_log=False)
    write_objects(loader, objects, types)
    touched = tables.entities.dropna()
    chained = {
        "types": touched["type"].astype(str).tolist(),
        "ids": touched["id"].astype(str).tolist(),
    }
    between_batches()
    tx.run(cypher("ekg_ocel_delete_df"), chained, log=name).consume()
    tx.run(cypher("ekg_ocel_chain_df"), chained, log=name).consume()
    for kind in classes:
        between_batches()
        tx.run(cypher("ekg_ocel_begins"), chained, log=name, type=kind.type).consume()
        tx.run(cypher("ekg_ocel_delete_df_c"), log=name, type=kind.type).consume()
        tx.run(cypher("ekg_aggregate_df_c"), log=name, type=kind.type, sources=None).consume()
    tx.run(cypher("ekg_log_summary"), log=name, summary=summary).consume()
