"""Aggregated EKG models from Neo4j (thesis 7.1.2, EKG-discovery; figure 7.7).

A stored log's events are aggregated into classes by a key (``activity``, ``activity,robot``,
``activity,robot,msg_id`` ...; robotale.ekg builds the Class nodes and DF_C edges, here they
are built on demand for a key the log was not ingested with). The model shows:

- one node per class, labelled with its key values and the number of activity instances it
  aggregates (each instance counted once, by the event that ends it); its ``events`` and its
  in-progress ``samples`` (continuous data, never instances) are counted apart;
- the DF_C edges of the chosen entity types (``robot``: each robot's own flow; ``msg_id``:
  the flow of each message across robots), each edge naming its entity type;
- ``COMM`` edges between the classes of a message's send and receive events, with the number
  of messages and their latency;
- an entry node per entity joined to the class of its first event; when a type has many
  entities (messages), one entry node stands for all of them, with counts on its edges.

Every query is a file ``cypher/discover_*.cypher``, run with parameters.
"""

from __future__ import annotations

from collections import Counter
from collections.abc import Sequence
from typing import Any

import pandas as pd

from robotale.discovery.graph import Edge, Node, ProcessGraph
from robotale.ekg.aggregate import aggregate as build_classes
from robotale.ekg.aggregate import aggregation_key, class_type, ensure_begins
from robotale.ekg.columnar import stored_table
from robotale.ekg.connection import read_rows, session_driver
from robotale.ekg.keys import DISCOVERY_KEY
from robotale.ekg.logs import log_info
from robotale.errors import InputError
from robotale.queries import cypher

COMM = "COMM"
#: above this many entities of a type, one entry node stands for all of them
ENTRY_NODES_PER_TYPE = 12


def discover_ekg(
    log: str,
    aggregate: str | Sequence[str] | None = None,
    entities: Sequence[str] | None = None,
    *,
    driver: Any = None,
) -> ProcessGraph:
    """The class graph of the stored log ``log`` aggregated by ``aggregate`` (default:
    activity and robot), with the DF_C edges of the entity types ``entities`` (default: all
    the log has)."""
    if driver is None:
        with session_driver() as connected:
            return discover_ekg(log, aggregate, entities, driver=connected)
    info = log_info(driver, log)
    key = aggregation_key(aggregate or DISCOVERY_KEY)
    kind = class_type(key)
    if kind not in (info["classTypes"] or []):
        build_classes(driver, log, key)
    else:
        ensure_begins(driver, log, kind)
    types = _entity_types(info, entities, log)
    graph = ProcessGraph(
        kind="ekg", info={"log": log, "aggregate": key, "class_type": kind, "entities": types}
    )
    graph.nodes = class_nodes(_run(driver, "discover_classes", log=log, type=kind), key)
    graph.edges = df_c_edges(_run(driver, "discover_df_c", log=log, type=kind, entityTypes=types))
    graph.edges += comm_edges(_run(driver, "discover_comm_c", log=log, type=kind))
    for entity_type in types:
        rows = _run(driver, "discover_entry_nodes", log=log, type=kind, entityType=entity_type)
        nodes, edges = entry_graph(entity_type, rows)
        graph.nodes += nodes
        graph.edges += edges
    return graph


def read_stored_log(log: str, *, driver: Any = None, hint: str | None = None) -> pd.DataFrame:
    """The events of a stored log as a canonical event log (pm4py column names, the column
    types the log was read with), from its columnar copy (:mod:`robotale.ekg.columnar`)."""
    if driver is None:
        with session_driver() as connected:
            return read_stored_log(log, driver=connected, hint=hint)
    return stored_table(driver, log, hint)


def _run(driver: Any, query: str, **parameters: Any) -> list[dict[str, Any]]:
    return read_rows(driver, cypher(query), **parameters)


def _entity_types(info: dict[str, Any], chosen: Sequence[str] | None, log: str) -> list[str]:
    known = list(info["entityTypes"] or [])
    if chosen is None:
        return known
    unknown = [name for name in chosen if name not in known]
    if unknown:
        raise InputError(
            f"Log {log!r} has no entity type {unknown[0]!r}; its entity types are "
            f"{', '.join(known) or 'none'}."
        )
    return list(chosen)


def class_nodes(rows: list[dict[str, Any]], key: list[str]) -> list[Node]:
    nodes = []
    for row in rows:
        values = {name: row["properties"].get(name) for name in key}
        robots = sorted(str(r) for r in row["robots"] if r is not None)
        robot = values.get("robot") if "robot" in values else None
        # a class counts its activity instances; its events and in-progress samples are
        # told apart, never added to them
        counts = {"events": int(row["events"]), "samples": int(row["samples"])}
        nodes.append(
            Node(
                id=row["id"],
                label=_class_label(values),
                count=int(row["instances"]),
                robot=robot if robot is not None else (robots[0] if len(robots) == 1 else None),
                robots=robots,
                properties=values | counts,
            )
        )
    return nodes


def _class_label(values: dict[str, Any]) -> str:
    """``explore (drone)``: the activity, then the other key values."""
    activity = values.get("activity")
    others = [str(v) for k, v in values.items() if k != "activity" and v is not None]
    head = str(activity) if activity is not None else " / ".join(others)
    rest = others if activity is not None else []
    return f"{head} ({', '.join(rest)})" if rest else head


def df_c_edges(rows: list[dict[str, Any]]) -> list[Edge]:
    return [_edge(row, row["entityType"]) for row in rows]


def comm_edges(rows: list[dict[str, Any]]) -> list[Edge]:
    return [_edge(row, COMM) for row in rows]


def _edge(row: dict[str, Any], entity_type: str) -> Edge:
    return Edge(
        source=row["source"],
        target=row["target"],
        count=int(row["count"]),
        label=str(int(row["count"])),
        entity_type=entity_type,
        durations={"mean": row["meanSeconds"], "median": row["medianSeconds"]},
    )


def entry_graph(entity_type: str, rows: list[dict[str, Any]]) -> tuple[list[Node], list[Edge]]:
    """Entry nodes of one entity type: one per entity, or one for all when there are many.

    An entity begins once per case it appears in (directly-follows never crosses a case), so
    an edge counts the cases in which the entity began at that class (``cases``, stored with
    the classes as BEGINS edges).
    """
    entities = sorted({row["entity"] for row in rows})
    if len(entities) <= ENTRY_NODES_PER_TYPE:
        nodes = [_entity_node(f"{entity_type}:{e}", str(e), 1, entity_type) for e in entities]
        starts = {(row["entity"], row["class"]): int(row["cases"]) for row in rows}
        edges = [
            Edge(f"{entity_type}:{e}", c, n, str(n) if n > 1 else "", entity_type)
            for (e, c), n in sorted(starts.items())
        ]
        return nodes, edges
    node_id = f"{entity_type}:*"
    node = _entity_node(node_id, f"{entity_type} ({len(entities)})", len(entities), entity_type)
    counts: Counter[str] = Counter()
    for row in rows:
        counts[row["class"]] += int(row["cases"])
    edges = [Edge(node_id, c, n, str(n), entity_type) for c, n in sorted(counts.items())]
    return [node], edges


def _entity_node(node_id: str, label: str, count: int, entity_type: str) -> Node:
    return Node(
        id=node_id,
        label=label,
        count=count,
        kind="entity",
        properties={"entity_type": entity_type},
    )
