"""Run an aggregation specification on a stored log, undo its steps, read any level.

Each step (:mod:`robotale.ekg.spec`) collapses the events, or the entities of one type, that
no earlier step collapsed and that pass its ``where`` into ``Aggregate`` nodes, one per
group: the nodes are taken with their properties (events from the log's columnar copy, their
``where`` evaluated in pandas by :mod:`robotale.ekg.where_table`; entities read from Neo4j),
grouped in pandas (:mod:`robotale.ekg.groups`) and the aggregates written in batches, with
the ids of the nodes each replaces as lists (``AggregateMembers`` nodes, a few writes per
aggregate rather than one per member). Then the CORR,
DF and COMM edges of those nodes are lifted to the aggregates, counted: computed in memory
from the log's event table (:mod:`robotale.ekg.lift`), nothing read back from the graph, and
written in batches. The graph after steps 1 .. k is level k: its aggregates and the lifted
edges between them.

The steps of one specification are grouped in memory first, all of them, and then written;
their lifted edges are those of the level the specification ends at (as OCEAN relates its
classes once, after its steps): an edge of a node that a later step of the same
specification collapses is lifted once, between the two aggregates, not first to the node
and again to its aggregate. Most edges of a log reach such a node (nine in ten for
OCEAN's logistics specification at 1.2M events), and creating the edges is most of the work.

A step is kept or undone as a unit: if writing it fails, what it wrote is removed again, and
``undo`` removes a step and the ones stacked on it; the steps of its specification before it
then get the edges to the nodes it held (:func:`_relink`), so the graph is the one that
specification would have written without the undone steps. Steps are numbered per log, so a
second specification stacks on the first.
"""

from __future__ import annotations

import shlex
import time
import weakref
from collections.abc import Callable, Collection, Sequence
from concurrent.futures import Future, ThreadPoolExecutor
from contextlib import suppress
from dataclasses import asdict, dataclass, replace
from typing import Any

import numpy as np
import pandas as pd
from neo4j import Driver
from neo4j.exceptions import DriverError, Neo4jError
from neo4j.time import DateTime

from robotale.ekg.build import ensure_schema, undo_after_failure
from robotale.ekg.columnar import build_of
from robotale.ekg.connection import database, read_autocommit
from robotale.ekg.groups import aggregate_table
from robotale.ekg.interrupt import DeferredInterrupt
from robotale.ekg.lift import FREE, LogEdges
from robotale.ekg.load import BATCH, Loader, neo4j_values
from robotale.ekg.logs import BUILD_QUERY, log_info
from robotale.ekg.spec import AggrStep
from robotale.ekg.where import Condition, parse_where
from robotale.ekg.where_table import matching
from robotale.ekg.writelock import log_write_lock, log_write_lock_reading
from robotale.errors import InputError, LogNotFound
from robotale.queries import cypher, statements

#: the properties every aggregate has; a group-by key of one of these names is only in ``name``
OWN_PROPERTIES = ("log", "step", "id", "name", "count", "origin", "key", "type")
#: the most member ids one AggregateMembers node lists
MEMBERS_PART = 100_000
#: lifted-edge batches in flight: every edge reaches one of the step's few aggregates, yet
#: Neo4j creates edges on one node from two transactions without waiting (measured on a
#: busy 2-core machine: no slower than one at a time; on a quiet one the second core helps)
LIFT_WORKERS = 2
#: the most lifted edges a step writes in one transaction per worker
LIFT_BATCH_MOST = 10_000
#: what a run reads in the transaction that takes the log's lock (parameters ``$log`` and
#: ``$types``, the entity types its steps name): the Log node's description and counts, the
#: steps stored, the build its columnar copy belongs to, the entities' property keys
_RUN_READS = [
    cypher("aggr_run_state"),
    cypher("aggr_steps"),
    cypher(BUILD_QUERY),
    cypher("aggr_node_keys"),
]
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
    _ensure_schema(driver)
    # what the run checks and reads of the Log node (the build its columnar copy belongs to)
    # and of its entities' keys is read with the lock, in its transaction: one commit, and
    # no round trip of its own
    types = sorted({s.ent_type for s in steps if s.ent_type is not None})
    with log_write_lock_reading(
        driver, log, "aggregating", _RUN_READS, log=log, types=types
    ) as held:
        state, stored, build, node_keys = held.rows
        if not state or not build:
            raise LogNotFound(log)
        info = state[0]
        _refuse_legacy(log, stored)
        first = int(stored[-1]["step"]) + 1 if stored else 1
        types_built = info.get("entityTypes") or []
        keys = _node_keys(node_keys)
        with ThreadPoolExecutor(max_workers=1) as pool:
            # the entity steps' nodes read from Neo4j while the log's copy is read here
            entity_rows = _start_entity_reads(pool, driver, log, info, steps, first, keys)
            edges = LogEdges.of_log(driver, log, types_built, build_of(log, build[0]))
            keys[None] = _event_keys(edges.events)
            plans = [_plan(driver, log, info, s, n, keys) for n, s in enumerate(steps, first)]
            read = {number: rows.result() for number, rows in entity_rows.items()}
        results: list[StepResult] = []
        if first > 1:
            edges.read_memberships(driver, log)
        events = len(edges.free_events())
        entities = int(info["entities"]) - edges.held_entities()
        grouped: list[tuple[_Plan, pd.DataFrame, float]] = []
        for plan in plans:  # in memory, each on what the ones before it left
            started = time.perf_counter()
            table = _group(driver, log, plan, edges, read.get(plan.number))
            grouped.append((plan, table, time.perf_counter() - started))
        try:
            for plan, table, seconds in grouped:
                result = _write_or_undo(driver, log, plan, table, edges, first, (events, entities))
                result = replace(result, seconds=result.seconds + seconds)
                events, entities = result.final_events, result.final_entities
                results.append(result)
        except BaseException:  # the steps before the one that failed are kept, complete
            with suppress(Neo4jError, DriverError, OSError):  # else they stay 'writing'
                _finish(driver, log, results)
            raise
        if results:  # recorded complete as the lock is given back, in its transaction
            held.with_release(cypher("aggr_step_finish"), log=log, steps=_finished(results))
        return results


def undo(driver: Driver, log: str, step: int | None = None) -> list[int]:
    """Undo step ``step`` of ``log`` and every step stacked on it (default: the last step);
    returns the steps undone, none when there are none."""
    log_info(driver, log)
    with log_write_lock(driver, log, "undoing aggregation steps of"):
        rows = list_steps(driver, log)
        numbers = [row["step"] for row in rows]
        if step is None:
            step = numbers[-1] if numbers else None
        if step is None:
            return []
        if step not in numbers:
            raise InputError(
                f"The log {log!r} has no aggregation step {step}; it has "
                f"{', '.join(map(str, numbers)) or 'none'}."
            )
        run = int(rows[numbers.index(step)]["run"])
        if run < step:  # earlier steps of its specification lack the edges to its nodes
            info = log_info(driver, log)
            edges = LogEdges.of_log(driver, log, info.get("entityTypes") or [])
            edges.read_memberships(driver, log)
            last = max(int(r["step"]) for r in rows if int(r["run"]) == run)
            held = edges.holder[edges.holder >= 0]
            ours = np.flatnonzero(edges.holder >= 0)[edges.levels[held] <= last]
            _delete_steps(driver, log, step)
            freed = np.intersect1d(edges.release(step), ours)
            _relink(driver, log, edges, range(run, step), freed)
        else:
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


def _group(
    driver: Driver, log: str, plan: _Plan, edges: LogEdges, read: dict[str, Any] | None = None
) -> pd.DataFrame:
    """The aggregates of ``plan``'s step (one row each, with its members' codes), recorded in
    ``edges`` as holding their members (their element ids once they are written); ``read``:
    an entity step's nodes as :func:`_entity_rows` read them, if they are read already."""
    step, number = plan.step, plan.number
    if step.origin == "Event":
        nodes = _event_nodes(edges, plan)
    else:
        nodes = _read_nodes(driver, log, plan, edges, read)
    table = aggregate_table(step, number, nodes, set(plan.times) & set(plan.reads))
    if len(table):
        sizes = table["count"].astype(int).to_numpy()
        members = np.concatenate([np.asarray(group, dtype=np.int64) for group in table["members"]])
        holders = np.repeat(table["id"].to_numpy(dtype=object), sizes).tolist()
        edges.hold(members, holders, [None] * len(holders), number)
    return table


def _write_or_undo(
    driver: Driver,
    log: str,
    plan: _Plan,
    table: pd.DataFrame,
    edges: LogEdges,
    run: int,
    before: tuple[int, int],
) -> StepResult:
    """Write the grouped step; if that fails, remove it again, and give the steps of its
    run before it the edges to the nodes it and the later steps would have held."""
    step, number = plan.step, plan.number
    started = time.perf_counter()

    def remove() -> None:
        _delete_steps(driver, log, number)
        _relink(driver, log, edges, range(run, number), edges.release(number))

    try:
        with DeferredInterrupt() as interrupt:
            _write(driver, log, step, number, table, edges, run, interrupt.check)
    except BaseException as error:
        undo_after_failure(
            error,
            remove,
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
    node keys of this run (read once, all types together), by entity type (None: events)."""
    what = f"step {number}"
    entity_types = list(info.get("entityTypes") or [])
    if step.origin == "Entity" and step.ent_type not in entity_types:
        raise InputError(
            f"The log {log!r} has no entities of type {step.ent_type!r} for {what}; it has "
            f"{', '.join(entity_types) or 'none'}."
        )
    found, times = known.get(step.ent_type, (set(), []))
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


def _event_keys(events: pd.DataFrame) -> tuple[set[str], list[str]]:
    """The events' property keys and those that hold zoned times, from the event table."""
    keys = {str(c) for c in events.columns if events[c].notna().any()} | {"order"}
    times = [str(c) for c in events.columns if isinstance(events[c].dtype, pd.DatetimeTZDtype)]
    return keys, times


def _node_keys(rows: Sequence[dict[str, Any]]) -> dict[str | None, tuple[set[str], list[str]]]:
    """The property keys of the entities of each type the run's steps name and those that
    hold zoned times, from the ``rows`` of ``aggr_node_keys`` (read with the lock); a type
    without entities is left out."""
    return {str(row["type"]): (set(row["keys"]) - {"log"}, list(row["times"])) for row in rows}


def _event_nodes(edges: LogEdges, plan: _Plan) -> pd.DataFrame:
    """One row per event the step collapses, from the log's event table: ``node`` (its
    code) and a column per property read, the values as Neo4j holds them (times as Unix
    nanoseconds); for an entity type a group-by names, what the event is correlated to
    there (the id of the aggregate holding the entity, else the entity's id; joined by ``,``)."""
    free = edges.free_events()
    # only the columns the where and the step read: taking every column's rows cost more
    # than the rest of the step
    table = _event_columns(edges, plan.condition.names, free)
    chosen = free[matching(plan.condition, table[[n for n in plan.condition.names if n in table]])]
    rows = _event_columns(edges, plan.reads, chosen)
    frame = pd.DataFrame({"node": chosen})
    for name in plan.reads:
        column = rows[name] if name in rows else pd.Series([None] * len(rows), dtype=object)
        frame[name] = _as_stored(column, name in plan.times)
    for name in plan.resolved:
        frame[name] = _correlated(edges, chosen, name)
    return frame


def _event_columns(edges: LogEdges, names: Collection[str], rows: np.ndarray) -> pd.DataFrame:
    """The rows ``rows`` (positions) of the event table's columns among ``names``, and
    ``order`` (the positions)."""
    present = [n for n in dict.fromkeys(names) if n in edges.events.columns]
    return edges.events[present].iloc[rows].reset_index(drop=True).assign(order=rows)


def _as_stored(column: pd.Series, is_time: bool) -> pd.Series:
    """A column of the event table as Neo4j returns it (times: Unix nanoseconds); text stays
    in its column (grouped as it is: made Python strings, a million events' cost seconds)."""
    if isinstance(column.dtype, pd.StringDtype):
        return column
    if is_time:
        ticks = column.dt.tz_convert("UTC").dt.as_unit("ns")
        return pd.Series(ticks.array.asi8, dtype="Int64").where(ticks.notna().to_numpy(), None)
    return pd.Series(neo4j_values(column), dtype=object)


def _correlated(edges: LogEdges, events: np.ndarray, kind: str) -> np.ndarray:
    """For each of ``events`` (positions): what stands for its entities of type ``kind``,
    distinct, sorted and joined by ``,`` (None when it has none)."""
    event, entity = edges.corr["event"].to_numpy(), edges.corr["entity"].to_numpy()
    wanted = np.zeros(len(edges.events), dtype=bool)
    wanted[events] = True
    keep = wanted[event] & (edges.types[entity] == kind)
    event, entity = event[keep], entity[keep]
    held = edges.holder[entity]
    # (event, code of what stands for the entity) as one integer: distinct, by event
    nodes = len(edges.keys)
    at, code = np.divmod(np.unique(event * nodes + np.where(held >= 0, held, entity)), nodes)
    found = np.full(len(edges.events), None, dtype=object)
    if not len(at):
        none: np.ndarray = found[events]
        return none
    starts = np.flatnonzero(np.r_[True, at[1:] != at[:-1]])
    ends = np.r_[starts[1:], len(at)]
    found[at[starts]] = edges.keys[code[starts]]
    # one value per event but for a few: joining each group in Python cost more than the rest
    for first, last in zip(starts[ends - starts > 1], ends[ends - starts > 1], strict=True):
        found[at[first]] = ",".join(sorted(str(k) for k in edges.keys[code[first:last]]))
    values: np.ndarray = found[events]
    return values


def _start_entity_reads(
    pool: ThreadPoolExecutor,
    driver: Driver,
    log: str,
    info: dict[str, Any],
    steps: Sequence[AggrStep],
    first: int,
    keys: dict[str | None, tuple[set[str], list[str]]],
) -> dict[int, Future[dict[str, Any]]]:
    """The reads of the entity steps' nodes (:func:`_entity_rows`), by step number, started
    in ``pool``: Neo4j answers them while this process reads the log's columnar copy (at 35k
    events the reads were a tenth of the run, waited for one after the other). None when a
    step does not pass its check: the checks are made again, in order, to say which."""
    plans: list[_Plan] = []
    for number, step in enumerate(steps, first):
        if step.origin == "Entity":
            try:
                plans.append(_plan(driver, log, info, step, number, keys))
            except InputError:
                return {}
    return {plan.number: pool.submit(_entity_rows, driver, log, plan) for plan in plans}


def _entity_rows(driver: Driver, log: str, plan: _Plan) -> dict[str, Any]:
    """The entities an entity step reads (those an earlier step collapses among them), as one
    row of columns: ``ids`` and ``values`` (a list of the properties read per entity)."""
    step, reads, condition = plan.step, plan.reads, plan.condition
    text = cypher("aggr_read_entities").replace(_WHERE_MARKER, condition.cypher)
    parameters: dict[str, Any] = {
        "log": log,
        "properties": reads,
        "times": [t for t in plan.times if t in reads],
        "type": step.ent_type,
    }
    # with the lock held: one round trip, no commit of its own
    return dict(read_autocommit(driver, text, {**condition.parameters, **parameters})[0])


def _read_nodes(
    driver: Driver, log: str, plan: _Plan, edges: LogEdges, row: dict[str, Any] | None = None
) -> pd.DataFrame:
    """One row per entity the step collapses: ``node`` (its code) and a column per property
    read; read from Neo4j (an entity's attributes may be set after the log was built), unless
    ``row`` holds them read already (:func:`_entity_rows`)."""
    if row is None:
        row = _entity_rows(driver, log, plan)
    reads = plan.reads
    values = row["values"]
    frame = pd.DataFrame(values, columns=reads) if values else pd.DataFrame(columns=reads)
    codes = edges.entity_codes(str(plan.step.ent_type), [str(i) for i in row["ids"]])
    frame.insert(0, "node", codes)
    return frame[edges.holder[codes] == FREE].reset_index(drop=True)


def _write(
    driver: Driver,
    log: str,
    step: AggrStep,
    number: int,
    table: pd.DataFrame,
    edges: LogEdges,
    run: int,
    between_batches: Callable[[], None],
) -> None:
    """Step ``number``: its record, aggregates, member lists, and the lifted edges it owns:
    those of its aggregates whose other end stands, at the level its run ends at, at this
    step or an earlier one (an edge to an aggregate of a later step is that step's). The
    record says 'writing' until :func:`_finish`."""
    record: dict[str, Any] = {"step": number, "spec": step.text(), "run": run}
    if not len(table):  # else the aggregates' first batch writes the record
        driver.execute_query(cypher("aggr_step_begin"), record, log=log, database_=database())
    loader = Loader(driver, log, None, between_batches)
    if len(table):
        own = [c for c in table.columns if c not in ("id", "name", "count", "members")]
        stored = [c for c in own if c not in OWN_PROPERTIES]
        together, apart = _members_with_batches(_member_parts(table, edges))
        created = loader.run(
            "aggr_create_aggregates",
            {
                "ids": table["id"].tolist(),
                "names": table["name"].tolist(),
                "counts": table["count"].astype(int).tolist(),
            },
            {"properties": {c: _storable(table[c]) for c in stored}},
            {
                "memberOf": [[p[0] for p in batch] for batch in together],
                "parts": [[p[1] for p in batch] for batch in together],
                "members": [[p[2] for p in batch] for batch in together],
            },
            **record,
            origin=step.origin,
            type=step.ent_type,
            key=[key.name for key in step.group_by],
        )
        edges.written(table["id"].tolist(), created, number)
        _write_members(driver, log, number, apart, between_batches)
        lifted = edges.lift_level(number)
        _write_lifted(driver, log, number, lifted, edges, between_batches)


def _write_lifted(
    driver: Driver,
    log: str,
    number: int,
    lifted: pd.DataFrame,
    edges: LogEdges,
    between_batches: Callable[[], None],
) -> None:
    """The lifted edges of step ``number``, both ends by element id (the events' and
    entities' read once per run, :meth:`LogEdges.ends`), :data:`LIFT_WORKERS` batches in
    flight."""
    source, target = lifted["source"].to_numpy(), lifted["target"].to_numpy()
    # grouped by the aggregate they reach: two batches in flight touch different aggregates
    # rather than both waiting on each of the step's few
    reached = np.where(pd.isna(edges.element_ids[source]), target, source)
    order = np.argsort(reached, kind="stable")
    lifted, source, target = lifted.iloc[order], source[order], target[order]
    loader = Loader(
        driver, log, None, between_batches, workers=LIFT_WORKERS, batch=_lift_batch(len(lifted))
    )
    loader.run(
        "aggr_create_lifted",
        {
            "kinds": lifted["kind"].tolist(),
            # None, not a text column's NaN, where an edge has no entity type (not DF)
            "entityTypes": neo4j_values(lifted["entityType"]),
            "counts": lifted["count"].astype(int).tolist(),
            "sources": edges.ends(driver, log, source).tolist(),
            "targets": edges.ends(driver, log, target).tolist(),
        },
        step=number,
    )


def _lift_batch(edges: int) -> int:
    """Rows per transaction of a step's ``edges`` lifted edges: one batch per worker when
    those are at most :data:`LIFT_BATCH_MOST` rows each (each batch costs two round trips,
    its query and its commit: at 35k events batches of :data:`BATCH` were most of the run's
    round trips), else :data:`BATCH` as before (a large step's transactions keep their size)."""
    each = -(-edges // LIFT_WORKERS)
    return max(BATCH, each) if each <= LIFT_BATCH_MOST else BATCH


def _relink(driver: Driver, log: str, edges: LogEdges, steps: range, freed: np.ndarray) -> None:
    """Give the aggregates of ``steps`` (written with the steps after them in one run, which
    are undone now) their lifted edges to the nodes in ``freed``: those nodes were held by
    the undone steps, so those edges went to their aggregates. ``edges`` holds the nodes as
    the graph does now."""
    if not freed.size:
        return
    for number in steps:
        lifted = edges.lift(edges.aggregates_of(number), others=freed)
        if len(lifted):
            _write_lifted(driver, log, number, lifted, edges, lambda: None)


#: one member list part: the aggregate's id, the part's number, the members' ids
_Part = tuple[str, int, list[str]]


def _member_parts(table: pd.DataFrame, edges: LogEdges) -> list[list[_Part]]:
    """Per aggregate (row of ``table``), its member lists: the ids of its members in parts
    of at most :data:`MEMBERS_PART`."""
    parts: list[list[_Part]] = []
    for aggregate, group in zip(table["id"], table["members"], strict=True):
        # the keys are texts already: one list of them, sliced, instead of a str() per member
        keys = edges.keys[np.asarray(group, dtype=np.int64)].tolist()
        parts.append(
            [
                (aggregate, part, keys[start : start + MEMBERS_PART])
                for part, start in enumerate(range(0, len(keys), MEMBERS_PART))
            ]
        )
    return parts


def _members_with_batches(parts: list[list[_Part]]) -> tuple[list[list[_Part]], list[_Part]]:
    """The member lists that go with the aggregates' batches (per batch of :data:`BATCH`
    aggregates: all of theirs when they list at most :data:`MEMBERS_PART` ids together, else
    none) and those written apart. A small step's lists then cost no round trip of their
    own; a large step's stay in transactions of their own size."""
    together: list[list[_Part]] = []
    apart: list[_Part] = []
    for start in range(0, len(parts), BATCH):
        batch = [part for row in parts[start : start + BATCH] for part in row]
        if sum(len(part[2]) for part in batch) <= MEMBERS_PART:
            together.append(batch)
        else:
            together.append([])
            apart.extend(batch)
    return together, apart


def _write_members(
    driver: Driver,
    log: str,
    number: int,
    parts: list[_Part],
    between_batches: Callable[[], None],
) -> None:
    """The member lists ``parts`` of step ``number``'s aggregates, a few parts per
    transaction (at most about :data:`MEMBERS_PART` ids)."""
    batch: list[_Part] = []
    for index, item in enumerate(parts):
        batch.append(item)
        if sum(len(b[2]) for b in batch) >= MEMBERS_PART or index == len(parts) - 1:
            between_batches()
            driver.execute_query(
                cypher("aggr_create_members"),
                log=log,
                step=number,
                aggregates=[b[0] for b in batch],
                parts=[b[1] for b in batch],
                members=[b[2] for b in batch],
                database_=database(),
            )
            batch = []


def _storable(column: pd.Series) -> list[Any]:
    """An aggregate column as values Neo4j stores; times stay Neo4j times (nanoseconds)."""
    if any(isinstance(v, DateTime) for v in column):
        return [v if isinstance(v, DateTime) else None for v in column]
    return neo4j_values(column)


#: the constraints of cypher/ekg_schema.cypher that aggregation steps rely on
_AGGREGATION_CONSTRAINTS = ["ekg_aggregate_key", "ekg_aggregation_step_key"]


#: the drivers (and their databases) whose schema a run has seen to: once per process
_SCHEMA_SEEN: weakref.WeakKeyDictionary[Driver, set[str]] = weakref.WeakKeyDictionary()


def _ensure_schema(driver: Driver) -> None:
    """:func:`ensure_schema` unless the aggregation's constraints are there already (a log
    built by this version has them): one question instead of ten statements, asked once per
    driver and database (constraints, once there, stay: nothing of robotale drops them)."""
    seen = _SCHEMA_SEEN.setdefault(driver, set())
    if database() in seen:
        return
    records = read_autocommit(
        driver, cypher("aggr_schema_present"), {"names": _AGGREGATION_CONSTRAINTS}
    )
    if int(records[0]["present"]) < len(_AGGREGATION_CONSTRAINTS):
        ensure_schema(driver)
    seen.add(database())


def _finish(driver: Driver, log: str, results: Sequence[StepResult]) -> None:
    """Record the steps ``results`` as complete, with their counts (a step's record says
    'writing' until then, as a run cut short leaves its last step)."""
    if results:
        driver.execute_query(
            cypher("aggr_step_finish"), log=log, steps=_finished(results), database_=database()
        )


def _finished(results: Sequence[StepResult]) -> list[dict[str, int]]:
    """The parameter ``$steps`` of ``aggr_step_finish``: all of a run's steps in one write."""
    return [{"step": r.step, "aggregates": r.aggregates, "members": r.members} for r in results]


def _legacy_steps(stored: Sequence[dict[str, Any]], step: int = 1) -> list[int]:
    """The steps from ``step`` on of ``stored`` (:func:`list_steps`) that earlier versions
    of robotale wrote: their members are marked on the nodes themselves, not listed."""
    return [int(row["step"]) for row in stored if row["legacy"] and int(row["step"]) >= step]


def _refuse_legacy(log: str, stored: Sequence[dict[str, Any]]) -> None:
    """A step stacked on steps whose members are not listed would collapse those members
    again: refuse, saying how to redo them."""
    legacy = _legacy_steps(stored)
    if legacy:
        listed = ", ".join(map(str, legacy))
        raise InputError(
            f"The aggregation step(s) {listed} of log {log!r} were written by an earlier version "
            "of robotale, which kept their members in another form: undo them with "
            f"`robotale aggregate {shlex.quote(log)} --undo {legacy[0]}` and run them again."
        )


def _delete_steps(driver: Driver, log: str, step: int) -> None:
    legacy = _legacy_steps(list_steps(driver, log), step)
    with driver.session(database=database()) as session:
        if legacy:  # their members carry marks, which go with them
            for statement in statements("aggr_undo_marks"):
                session.run(statement, log=log, step=step).consume()
        for statement in statements("aggr_undo"):
            session.run(statement, log=log, step=step).consume()
