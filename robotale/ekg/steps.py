"""Run an aggregation specification on a stored log, undo its steps, read any level.

Each step (:mod:`robotale.ekg.spec`) collapses the events, or the entities of one type, that
no earlier step collapsed and that pass its ``where`` into ``Aggregate`` nodes, one per
group: the nodes are read with their properties, grouped in pandas
(:mod:`robotale.ekg.groups`) and the aggregates written in batches; each node they replace
records its aggregate's id in its property ``_aggregate``. Then the CORR, DF and COMM edges
of those nodes are lifted to the aggregates, counted: computed in memory from one reading of
the log's edges per run (:mod:`robotale.ekg.lift`) and written in batches. The graph after
steps 1 .. k is level k: its aggregates and the lifted edges between them.

A step is kept or undone as a unit: if writing it fails, what it wrote is removed again, and
``undo`` removes a step and the ones stacked on it. Steps are numbered per log, so a second
specification stacks on the first.
"""

from __future__ import annotations

import shlex
import time
from collections.abc import Callable, Sequence
from dataclasses import asdict, dataclass
from typing import Any

import pandas as pd
from neo4j import Driver
from neo4j.time import DateTime

from robotale.ekg.build import ensure_schema, undo_after_failure
from robotale.ekg.connection import database
from robotale.ekg.groups import aggregate_table
from robotale.ekg.interrupt import DeferredInterrupt
from robotale.ekg.lift import LogEdges
from robotale.ekg.load import Loader, neo4j_values
from robotale.ekg.logs import log_info
from robotale.ekg.spec import AggrStep
from robotale.ekg.where import Condition, parse_where
from robotale.ekg.writelock import log_write_lock
from robotale.errors import InputError
from robotale.queries import cypher, statements

#: the properties every aggregate has; a group-by key of one of these names is only in ``name``
OWN_PROPERTIES = ("log", "step", "id", "name", "count", "origin", "key", "type")
#: how many events tell which properties hold times
KEY_SAMPLE = 10_000
#: the marker in ``aggr_read_*.cypher`` that a step's checked condition replaces
_WHERE_MARKER = "true /*WHERE*/"


@dataclass(frozen=True)
class StepResult:
    """What one step did; the four counts are OCEAN's verification table."""

    step: int
    spec: str
    aggregates: int
    members: int
    initial_events: int
    final_events: int
    initial_entities: int
    final_entities: int
    seconds: float

    def to_dict(self) -> dict[str, Any]:
        return asdict(self)


def run_spec(driver: Driver, log: str, steps: Sequence[AggrStep]) -> list[StepResult]:
    """Run ``steps`` on the stored log ``log``, each stacked on the ones before (also those
    of earlier runs). Every step is checked against the log before the first one runs, so a
    specification that names something the log lacks writes nothing."""
    info = log_info(driver, log)
    ensure_schema(driver)
    with log_write_lock(driver, log, "aggregating"):
        first = _last_step(driver, log) + 1
        keys: dict[str | None, tuple[set[str], list[str]]] = {}
        plans = [_plan(driver, log, info, step, n, keys) for n, step in enumerate(steps, first)]
        results: list[StepResult] = []
        events, entities = _unaggregated(driver, log)
        edges = LogEdges.read(driver, log, stacked=first > 1)
        for plan in plans:
            result = _run_or_undo(driver, log, plan, (events, entities), edges)
            events, entities = result.final_events, result.final_entities
            results.append(result)
        return results


def undo(driver: Driver, log: str, step: int | None = None) -> list[int]:
    """Undo step ``step`` of ``log`` and every step stacked on it (default: the last step);
    returns the steps undone, none when there are none."""
    log_info(driver, log)
    with log_write_lock(driver, log, "undoing aggregation steps of"):
        numbers = [row["step"] for row in list_steps(driver, log)]
        if step is None:
            step = numbers[-1] if numbers else None
        if step is None:
            return []
        if step not in numbers:
            raise InputError(
                f"The log {log!r} has no aggregation step {step}; it has "
                f"{', '.join(map(str, numbers)) or 'none'}."
            )
        _delete_steps(driver, log, step)
        return [n for n in numbers if n >= step]


def list_steps(driver: Driver, log: str) -> list[dict[str, Any]]:
    """The steps stored for ``log``: number, spec (JSON), status and counts."""
    records, _, _ = driver.execute_query(cypher("aggr_steps"), log=log, database_=database())
    return [record.data() for record in records]


def level_graph(driver: Driver, log: str, level: int) -> dict[str, list[dict[str, Any]]]:
    """The aggregates of level ``level`` (after steps 1 .. ``level``) and the lifted edges
    between them."""
    nodes, _, _ = driver.execute_query(
        cypher("aggr_level_nodes"), log=log, level=level, database_=database()
    )
    edges, _, _ = driver.execute_query(
        cypher("aggr_level_edges"), log=log, level=level, database_=database()
    )
    return {
        "aggregates": [dict(r["aggregate"]) for r in nodes],
        "edges": [r.data() for r in edges],
    }


def _run_or_undo(
    driver: Driver, log: str, plan: _Plan, before: tuple[int, int], edges: LogEdges
) -> StepResult:
    step, number = plan.step, plan.number
    started = time.perf_counter()
    nodes = _read_nodes(driver, log, plan)
    table = aggregate_table(step, number, nodes, set(plan.times) & set(plan.reads))
    try:
        with DeferredInterrupt() as interrupt:
            _write(driver, log, step, number, table, edges, interrupt.check)
    except BaseException as error:
        undo_after_failure(
            error,
            lambda: _delete_steps(driver, log, number),
            f"Aggregation step {number} of {log!r} failed",
            f"`robotale aggregate {shlex.quote(log)} --undo {number}`",
        )
    members = int(table["count"].sum())
    events, entities = before
    collapsed_events = members if step.origin == "Event" else 0
    return StepResult(
        step=number,
        spec=step.text(),
        aggregates=len(table),
        members=members,
        initial_events=events,
        final_events=events - collapsed_events,
        initial_entities=entities,
        final_entities=entities - (members - collapsed_events),
        seconds=time.perf_counter() - started,
    )


@dataclass(frozen=True)
class _Plan:
    """A step checked against the log, with what it reads."""

    step: AggrStep
    number: int
    reads: list[str]  # node properties
    resolved: list[str]  # entity types an event step groups by (through CORR)
    condition: Condition
    times: list[str]  # the properties that hold zoned times


def _plan(
    driver: Driver,
    log: str,
    info: dict[str, Any],
    step: AggrStep,
    number: int,
    known: dict[str | None, tuple[set[str], list[str]]],
) -> _Plan:
    """Check every name ``step`` uses against the log; what it will read. ``known``: the
    node keys already read in this run, by entity type (None: events)."""
    what = f"step {number}"
    entity_types = list(info.get("entityTypes") or [])
    if step.origin == "Entity" and step.ent_type not in entity_types:
        raise InputError(
            f"The log {log!r} has no entities of type {step.ent_type!r} for {what}; it has "
            f"{', '.join(entity_types) or 'none'}."
        )
    if step.ent_type not in known:  # the entities' keys are read from all of them: once
        known[step.ent_type] = _node_keys(driver, log, step.ent_type)
    found, times = known[step.ent_type]
    keys = set(found)
    resolved: list[str] = []
    if step.origin == "Event":  # a property the sampled events lack may be on later ones
        keys |= set(info.get("properties") or []) | {"id", "order", "timestamp"}
        resolved = [
            k.inputs[0]
            for k in step.group_by
            if k.kind == "property" and k.inputs[0] in entity_types
        ]
    reads = [name for name in step.reads() if name not in resolved]
    missing = [name for name in reads if name not in keys]
    if missing:
        nodes = "events" if step.origin == "Event" else f"{step.ent_type} entities"
        raise InputError(
            f"The {nodes} of log {log!r} have no property {missing[0]!r} for {what}; they have "
            f"{', '.join(sorted(keys)) or 'none'}."
        )
    condition = (
        parse_where(step.where, "n", keys, f"the where of {what}")
        if step.where
        else Condition("true", {}, frozenset())
    )
    return _Plan(step, number, reads, resolved, condition, times)


def _node_keys(driver: Driver, log: str, entity_type: str | None) -> tuple[set[str], list[str]]:
    # Events: a sample tells the types (their keys are on the Log node); entities: all.
    limit = KEY_SAMPLE if entity_type is None else 2**62
    records, _, _ = driver.execute_query(
        cypher("aggr_node_keys"), log=log, type=entity_type, limit=limit, database_=database()
    )
    row = records[0] if records else None
    if row is None:
        return set(), []
    return set(row["keys"]) - {"log"}, list(row["times"])


def _read_nodes(driver: Driver, log: str, plan: _Plan) -> pd.DataFrame:
    """One row per node the step collapses: ``node`` and a column per property read (for
    an entity type a group-by names: what the event is correlated to, joined by ``,``)."""
    step, reads, resolved, condition = plan.step, plan.reads, plan.resolved, plan.condition
    query = "aggr_read_events" if step.origin == "Event" else "aggr_read_entities"
    text = cypher(query).replace(_WHERE_MARKER, condition.cypher)
    parameters: dict[str, Any] = {
        "log": log,
        "properties": reads,
        "times": [t for t in plan.times if t in reads],
        "entityTypes": resolved,
        "type": step.ent_type,
    }
    records, _, _ = driver.execute_query(
        text, {**condition.parameters, **parameters}, database_=database()
    )
    row = records[0]
    values = row["values"]
    frame = pd.DataFrame(values, columns=reads) if values else pd.DataFrame(columns=reads)
    if resolved:
        found = row["entities"]
        for position, name in enumerate(resolved):
            frame[name] = [",".join(sorted(set(map(str, e[position])))) or None for e in found]
    nodes = row["nodes"]
    frame.insert(0, "node", nodes)
    return frame


def _write(
    driver: Driver,
    log: str,
    step: AggrStep,
    number: int,
    table: pd.DataFrame,
    edges: LogEdges,
    between_batches: Callable[[], None],
) -> None:
    driver.execute_query(
        cypher("aggr_step_begin"), log=log, step=number, spec=step.text(), database_=database()
    )
    loader = Loader(driver, log, None, between_batches)
    if len(table):
        own = [c for c in table.columns if c not in ("id", "name", "count", "members")]
        stored = [c for c in own if c not in OWN_PROPERTIES]
        created = loader.run(
            "aggr_create_aggregates",
            {
                "ids": table["id"].tolist(),
                "names": table["name"].tolist(),
                "counts": table["count"].astype(int).tolist(),
            },
            {"properties": {c: _storable(table[c]) for c in stored}},
            step=number,
            origin=step.origin,
            type=step.ent_type,
            key=[key.name for key in step.group_by],
        )
        sizes = table["count"].astype(int).tolist()
        owners = [node for node, size in zip(created, sizes, strict=True) for _ in range(size)]
        members = [str(m) for group in table["members"] for m in group]
        holders = [i for i, size in zip(table["id"], sizes, strict=True) for _ in range(size)]
        loader.run("aggr_create_members", {"members": members, "aggregates": holders})
        lifted = edges.lift(members, owners)
        if len(lifted):
            # every lifted edge reaches one of this step's few aggregates: one batch at a time
            Loader(driver, log, None, between_batches, workers=1).run(
                "aggr_create_lifted",
                {
                    "kinds": lifted["kind"].tolist(),
                    "sources": lifted["source"].tolist(),
                    "targets": lifted["target"].tolist(),
                    "entityTypes": lifted["entityType"].tolist(),
                    "counts": lifted["count"].astype(int).tolist(),
                },
                step=number,
            )
    driver.execute_query(
        cypher("aggr_step_finish"),
        log=log,
        step=number,
        counts={"aggregates": len(table), "members": int(table["count"].sum())},
        database_=database(),
    )


def _storable(column: pd.Series) -> list[Any]:
    """An aggregate column as values Neo4j stores; times stay Neo4j times (nanoseconds)."""
    if any(isinstance(v, DateTime) for v in column):
        return [v if isinstance(v, DateTime) else None for v in column]
    return neo4j_values(column)


def _last_step(driver: Driver, log: str) -> int:
    steps = list_steps(driver, log)
    return int(steps[-1]["step"]) if steps else 0


def _unaggregated(driver: Driver, log: str) -> tuple[int, int]:
    records, _, _ = driver.execute_query(cypher("aggr_unaggregated"), log=log, database_=database())
    return int(records[0]["events"]), int(records[0]["entities"])


def _delete_steps(driver: Driver, log: str, step: int) -> None:
    with driver.session(database=database()) as session:
        for statement in statements("aggr_undo"):
            session.run(statement, log=log, step=step).consume()
