"""The class graph of a stored log computed from its event table instead of read from Neo4j.

:func:`~robotale.discovery.ekg.discover_ekg` reads the Class nodes and the DF_C, COMM and
BEGINS edges a build wrote; the build computed them from the event table
(:func:`~robotale.ekg.tables.graph_tables`, :func:`~robotale.ekg.tables.class_tables`), so
the same tables computed again from the log's columnar copy give the same graph in time linear
in the log, with no query per class: a page drawing the class graph of a log nobody prepared
(a restarted dashboard, ``robotale ingest --pages visit``) waits for numpy, not for Neo4j.
Nodes and edges come in the order the Cypher queries give them (``ORDER BY``), so the two
answers are equal (``tests/discovery/test_ekg_table.py`` holds them side by side).
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numpy as np
import pandas as pd

from robotale.discovery.ekg import class_nodes, comm_edges, df_c_edges, entry_graph
from robotale.discovery.graph import ProcessGraph
from robotale.ekg.aggregate import class_type
from robotale.ekg.load import neo4j_values
from robotale.ekg.tables import (
    ClassTables,
    GraphTables,
    class_tables,
    graph_tables,
    instance_ends,
    property_name,
    utc_ticks,
)
from robotale.eventlog import schema


def computable(events: pd.DataFrame, key: Sequence[str], entity_types: Sequence[str]) -> bool:
    """Whether the event table ``events`` (canonical columns) has events, every property of
    ``key`` and every entity type: else the graph is read from Neo4j, which says what is
    missing (or aggregates by properties the table lacks)."""
    present = {property_name(column) for column in events.columns}
    return len(events) > 0 and bool(entity_types) and set(key) | set(entity_types) <= present


def table_class_graph(
    log: str, events: pd.DataFrame, key: Sequence[str], entity_types: Sequence[str]
) -> ProcessGraph:
    """The class graph of the log ``log`` (its event table ``events``) by ``key`` (Event
    property names) with the DF_C edges and entry nodes of ``entity_types``: what
    :func:`~robotale.discovery.ekg.discover_ekg` reads from the stored graph."""
    tables = graph_tables(events, entity_types)
    classes = class_tables(tables, key)
    kind = class_type(key)
    graph = ProcessGraph(
        kind="ekg",
        info={
            "log": log,
            "aggregate": list(key),
            "class_type": kind,
            "entities": list(entity_types),
        },
    )
    graph.nodes = class_nodes(_class_rows(tables.events, classes), list(key))
    graph.edges = df_c_edges(_df_c_rows(classes))
    graph.edges += comm_edges(_comm_rows(tables, classes))
    for entity_type in entity_types:
        nodes, edges = entry_graph(entity_type, _entry_rows(tables, classes, entity_type))
        graph.nodes += nodes
        graph.edges += edges
    return graph


def _class_rows(events: pd.DataFrame, classes: ClassTables) -> list[dict[str, Any]]:
    """``cypher/discover_classes.cypher``'s rows: each class's key values, its events, the
    activity instances among them, its in-progress samples and its robots, by id."""
    observed = classes.observed
    count = len(classes.classes)
    ends = instance_ends(events)
    samples = _is(events, "state", schema.INPROGRESS)
    totals = np.bincount(observed, minlength=count)
    instances = np.bincount(observed[ends & ~samples], minlength=count)
    sampled = np.bincount(observed[samples], minlength=count)
    robots = _robots(events, observed, count)
    values = {name: neo4j_values(classes.classes[name]) for name in classes.key}
    ids = classes.classes["id"].tolist()
    rows = [
        {
            "id": ids[row],
            "properties": {name: values[name][row] for name in classes.key},
            "events": int(totals[row]),
            "instances": int(instances[row]),
            "samples": int(sampled[row]),
            "robots": robots[row],
        }
        for row in range(count)
    ]
    return sorted(rows, key=lambda row: row["id"])


def _is(events: pd.DataFrame, column: str, value: str) -> np.ndarray:
    """Which events have ``value`` in ``column`` (none when the log has no such column)."""
    if column not in events.columns:
        return np.zeros(len(events), dtype=bool)
    codes, uniques = pd.factorize(events[column])
    return np.append(np.asarray(uniques, dtype=object) == value, False)[codes]


def _robots(events: pd.DataFrame, observed: np.ndarray, count: int) -> list[list[Any]]:
    """The distinct robots of each class's events (as Neo4j holds them), missing ones left
    out."""
    found: list[list[Any]] = [[] for _ in range(count)]
    if "robot" not in events.columns:
        return found
    codes, uniques = pd.factorize(events["robot"])
    present = codes >= 0
    pairs = np.unique(observed[present].astype(np.int64) * max(len(uniques), 1) + codes[present])
    names = neo4j_values(pd.Series(uniques))
    for row, robot in zip(*np.divmod(pairs, max(len(uniques), 1)), strict=True):
        found[int(row)].append(names[int(robot)])
    return found


def _df_c_rows(classes: ClassTables) -> list[dict[str, Any]]:
    """``cypher/discover_df_c.cypher``'s rows, ordered by entity type, source and target."""
    df_c = classes.df_c
    ids = classes.classes["id"].to_numpy(dtype=object)
    rows = pd.DataFrame(
        {
            "source": ids[df_c["source"].to_numpy(dtype=np.int64)],
            "target": ids[df_c["target"].to_numpy(dtype=np.int64)],
            "entityType": df_c["entityType"].to_numpy(dtype=object),
            "count": df_c["count"].to_numpy(),
            "meanSeconds": df_c["meanSeconds"].to_numpy(dtype=float),
            "medianSeconds": df_c["medianSeconds"].to_numpy(dtype=float),
        }
    )
    return _records(rows.sort_values(["entityType", "source", "target"]))


def _comm_rows(tables: GraphTables, classes: ClassTables) -> list[dict[str, Any]]:
    """``cypher/discover_comm_c.cypher``'s rows: the messages between each pair of classes,
    each counted once per pair (whatever its case), its latency from its first send event to
    its first receive event there."""
    comm = tables.comm
    if comm.empty:
        return []
    source = comm["source"].to_numpy(dtype=np.int64)
    target = comm["target"].to_numpy(dtype=np.int64)
    ticks = utc_ticks(tables.events)
    messages = pd.DataFrame(
        {
            "a": classes.observed[source],
            "b": classes.observed[target],
            "message": pd.factorize(comm["msgId"])[0],
            "sent": ticks[source],
            "received": ticks[target],
        }
    )
    first = messages.groupby(["a", "b", "message"], sort=False).min()
    sent_seconds, sent_part = np.divmod(first["sent"].to_numpy(), 1_000_000_000)
    received_seconds, received_part = np.divmod(first["received"].to_numpy(), 1_000_000_000)
    # as the query adds them: whole seconds apart, then the nanoseconds apart
    seconds = (received_seconds - sent_seconds) + (received_part - sent_part) / 1e9
    pairs = pd.DataFrame({"seconds": seconds}, index=first.index.droplevel("message"))
    by_pair = pairs.groupby(level=["a", "b"])["seconds"].agg(["size", "mean", "median"])
    ids = classes.classes["id"].to_numpy(dtype=object)
    rows = pd.DataFrame(
        {
            "source": ids[by_pair.index.get_level_values("a").to_numpy()],
            "target": ids[by_pair.index.get_level_values("b").to_numpy()],
            "count": by_pair["size"].to_numpy(),
            "meanSeconds": by_pair["mean"].to_numpy(),
            "medianSeconds": by_pair["median"].to_numpy(),
        }
    )
    return _records(rows.sort_values(["source", "target"]))


def _entry_rows(
    tables: GraphTables, classes: ClassTables, entity_type: str
) -> list[dict[str, Any]]:
    """``cypher/discover_entry_nodes.cypher``'s rows for ``entity_type``: each entity, the
    class it begins at and in how many cases."""
    entries = classes.entries
    entity = entries["entity"].to_numpy(dtype=np.int64)
    of_type = tables.entities["type"].to_numpy(dtype=object)[entity] == entity_type
    ids = classes.classes["id"].to_numpy(dtype=object)
    rows = pd.DataFrame(
        {
            "entity": tables.entities["id"].to_numpy(dtype=object)[entity[of_type]],
            "class": ids[entries["class"].to_numpy(dtype=np.int64)[of_type]],
            "cases": entries["cases"].to_numpy()[of_type],
        }
    )
    return _records(rows.sort_values(["entity", "class"]))


def _records(rows: pd.DataFrame) -> list[dict[str, Any]]:
    """The rows as plain Python values, as the driver gives a query's rows."""
    return rows.astype(object).to_dict(orient="records")
