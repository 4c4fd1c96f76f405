"""Build the event knowledge graph of one event log in Neo4j: :func:`build_ekg`.

The log is checked and turned into tables first (:mod:`robotale.ekg.tables`), so bad input is
refused before Neo4j is touched. If writing fails anyway (the server goes away, the user presses
Ctrl-C), what was written is removed again; a rebuild with ``replace=True`` writes the new log
under a temporary name and only swaps it in once it is complete, so a failed rebuild keeps the
old log.
"""

from __future__ import annotations

import dataclasses
import itertools
import shlex
import time
import uuid
from collections.abc import Callable, Sequence
from concurrent.futures import ThreadPoolExecutor, wait
from dataclasses import dataclass, field
from typing import NoReturn

import numpy as np
import pandas as pd
from neo4j import Driver
from neo4j.exceptions import DriverError, Neo4jError
from tqdm import tqdm

from robotale.ekg import disk_full
from robotale.ekg.aggregate import aggregation_key
from robotale.ekg.columnar import delete_copies, store_copy
from robotale.ekg.connection import database
from robotale.ekg.interrupt import DeferredInterrupt
from robotale.ekg.keys import DEFAULT_AGGREGATE, default_entities
from robotale.ekg.load import Loader, neo4j_values, within_batches
from robotale.ekg.logs import FAILED, delete_log, log_exists, log_info, log_run
from robotale.ekg.objects import write_objects
from robotale.ekg.tables import (
    ClassTables,
    GraphTables,
    class_tables,
    entity_types,
    graph_tables,
    log_values,
    property_name,
)
from robotale.ekg.writelock import log_write_lock
from robotale.errors import InputError, LogNotFound, ServerError
from robotale.eventlog.objects import Objects
from robotale.queries import cypher, statements
from robotale.timings import stage


@dataclass(frozen=True)
class BuildSummary:
    """What :func:`build_ekg` wrote."""

    log: str
    events: int
    entities: dict[str, int]
    corr: int
    df: dict[str, int]
    comm: int
    df_c: dict[str, int] = field(default_factory=dict)
    seconds: float = 0.0


def _exists_message(driver: Driver, name: str) -> str:
    """Why a log of that name is in the way, and the commands that clear it: a failed
    ingest's partial log is named as such."""
    delete = f"`robotale logs delete {shlex.quote(name)}`"
    try:
        info = log_info(driver, name)
    except LogNotFound:  # events without their Log node: what a very early failure leaves
        info = {"status": FAILED, "events": None}
    if info["status"] == FAILED:
        events = f" ({info['events']:,} events)" if info.get("events") is not None else ""
        return (
            f"The log {name!r} in Neo4j is what a failed ingest left{events}: remove it with "
            f"{delete}, or ingest again with --replace to rebuild it."
        )
    return (
        f"A log named {name!r} already exists in Neo4j; use --replace to rebuild it "
        f"or {delete} first."
    )


def refuse_existing(driver: Driver, name: str) -> None:
    """Refuse a new log of a name Neo4j already holds, in the sentence that says how to clear
    it: asked before a log is read, so a refused ingest answers at once whatever its size."""
    if log_exists(driver, name):
        raise InputError(_exists_message(driver, name))


def build_ekg(
    driver: Driver,
    log: pd.DataFrame,
    name: str,
    entities: Sequence[str] | None = None,
    aggregate: Sequence[str | Sequence[str]] = DEFAULT_AGGREGATE,
    replace: bool = False,
    source: str = "",
    progress: bool = True,
    objects: Objects | None = None,
    prepared: Prepared | None = None,
) -> BuildSummary:
    """Store ``log`` (a canonical event log) in Neo4j as the EKG named ``name``.

    ``entities`` are the columns whose values become Entity nodes (CORR and DF edges per
    entity type; default: ``robot`` and ``msg_id`` where present, else ``case``). Each item
    of ``aggregate`` is one aggregation key (``"activity"``, ``"activity,robot"``) that gets
    Class nodes and DF_C edges. An existing log of that name is refused unless ``replace``.
    ``objects``: the objects of an object-centric log (their attributes, qualifiers and
    relations, :mod:`robotale.ekg.objects`), written with the log and undone with it.
    ``prepared``: the tables :func:`prepare` computed of these arguments already.
    """
    started = time.perf_counter()
    with stage("compute the graph's tables"):
        prepared = prepared or prepare(log, entities, aggregate, name)
    chosen, tables, classes = prepared.entity_types, prepared.tables, prepared.classes
    with stage("the indexes and constraints"):
        ensure_schema(driver)
    # Checked under the lock: another ingest of this name may have finished a moment ago.
    with log_write_lock(driver, name, "ingesting") as run:
        if not replace:
            refuse_existing(driver, name)
        existing = replace and log_exists(driver, name)
        target = f"{name} (rebuilding {uuid.uuid4().hex[:8]})" if existing else name
        # under the lock: no other build of this name can come between the graph and its
        # copy. A new log's copy needs only its Log node: it is written beside the graph.
        copy = None if existing else _copying(driver, name, log)
        job = _Job(tables, classes, target, source, progress, run, objects, chosen, copy)
        with stage("write the graph"):
            summary = _write_or_undo(driver, job)
        if existing:
            _swap(driver, target, name)
            with stage("the columnar copy"):
                store_copy(driver, name, log)
    return dataclasses.replace(summary, log=name, seconds=time.perf_counter() - started)


@dataclass(frozen=True)
class Prepared:
    """A log checked and turned into the tables of its graph, before Neo4j is touched."""

    entity_types: list[str]
    tables: GraphTables
    classes: list[ClassTables]


def prepare(
    log: pd.DataFrame,
    entities: Sequence[str] | None,
    aggregate: Sequence[str | Sequence[str]],
    name: str,
) -> Prepared:
    """Check ``log`` and its name and compute its graph's tables (bad input is refused here)."""
    check_log_name(name)
    chosen = default_entities(log.columns) if entities is None else list(entities)
    tables = graph_tables(log, chosen)
    keys = unique_keys(aggregate)
    check_keys(tables.events, keys)
    check_key_sizes(tables, keys)
    return Prepared(chosen, tables, [class_tables(tables, key) for key in keys])


def unique_keys(aggregate: Sequence[str | Sequence[str]]) -> list[list[str]]:
    """The aggregation keys as property names, each once."""
    keys: list[list[str]] = []
    for key in map(aggregation_key, aggregate):
        if key not in keys:
            keys.append(key)
    return keys


def check_log_name(name: object) -> str:
    if not isinstance(name, str) or not name.strip() or len(name) > 200 or not name.isprintable():
        raise InputError(f"{name!r} is not a usable log name: give 1 to 200 printable characters.")
    return name


def ensure_schema(driver: Driver) -> None:
    """Create the constraints and indexes of ``cypher/ekg_schema.cypher`` if missing."""
    for statement in statements("ekg_schema"):
        driver.execute_query(statement, database_=database())


def ensure_schema_together(driver: Driver) -> None:
    """:func:`ensure_schema` with every statement in a session of its own at the same time.

    A uniqueness constraint's ``CREATE`` returns only once Neo4j has filled its index from the
    nodes already stored, so on a graph imported whole the statements one after another wait
    for the sum of those scans; together the scans of different labels overlap and the wait is
    about the longest (the events'). The first failure is raised once all have ended."""
    schema = statements("ekg_schema")
    with ThreadPoolExecutor(max_workers=len(schema)) as pool:
        running = [
            pool.submit(driver.execute_query, statement, database_=database())
            for statement in schema
        ]
        wait(running)
    for done in running:
        done.result()


def check_keys(events: pd.DataFrame, keys: list[list[str]]) -> None:
    for key in keys:
        entity_types(list(events.columns), key, what="aggregate by")


# Neo4j refuses index keys longer than about 8 kB with a long text that names no row; the
# ids of events, entities and classes are index keys (UTF-8 bytes; a margin for the log name).
KEY_BYTES = 4000


def check_key_sizes(tables: GraphTables, keys: list[list[str]]) -> None:
    """One sentence naming the event and column of the first value too long to be a key."""
    events = tables.events
    columns = {"id"} | {column for key in keys for column in key}
    columns |= set(tables.entities["type"].unique())  # entity types are event columns
    for column in sorted(c for c in columns if c in events.columns):
        text = events[column].astype("string").fillna("")
        # A character takes at most 4 bytes: only longer values need encoding to be measured.
        if not (text.str.len() > KEY_BYTES // 4).any():
            continue
        sizes = text.str.encode("utf-8").str.len()
        if (sizes > KEY_BYTES).any():
            row = int(sizes.to_numpy().argmax())
            raise InputError(
                f"Event {row + 1} of the log (id {str(events['id'].iloc[row])[:40]!r}) has "
                f"{int(sizes.iloc[row]):,} bytes as its {column}; {column} values become "
                f"keys of Neo4j's indexes, which take at most {KEY_BYTES:,} bytes: shorten it "
                "or leave that column out of --entities and --aggregate."
            )


@dataclass(frozen=True)
class _Job:
    tables: GraphTables
    classes: list[ClassTables]
    target: str  # the log's name, or a temporary one while an existing log is rebuilt
    source: str
    progress: bool
    run: str  # the id of this run's write lock, recorded on the Log node
    objects: Objects | None = None
    entity_types: Sequence[str] = ()
    copy: Callable[[], object] | None = None  # the columnar copy, kept beside the graph


def _copying(driver: Driver, name: str, log: pd.DataFrame) -> Callable[[], object]:
    def copy() -> object:
        with stage("the columnar copy (beside the graph)"):
            return store_copy(driver, name, log)

    return copy


def _write_or_undo(driver: Driver, job: _Job) -> BuildSummary:
    target = job.target
    since = disk_full.log_position()
    try:
        with DeferredInterrupt() as interrupt:
            return _write(driver, job, interrupt.check)
    except BaseException as error:
        if isinstance(error, Neo4jError) and (full := disk_full.out_of_disk(since)):
            _undo_after_full_disk(driver, job, full, error)
        if isinstance(error, Neo4jError | DriverError | OSError) and not _answers(driver):
            # Retrying the undo against a server that is gone would only take minutes.
            raise ServerError(
                f"Neo4j went away while the log {target!r} was written ({why(error)}); once it "
                "runs again, `robotale logs list` shows the log as failed and "
                f"`robotale logs delete {shlex.quote(target)}` removes it."
            ) from error
        undo_after_failure(
            error,
            lambda: _undo(driver, target, job.run),
            f"Writing the log {target!r} to Neo4j failed",
            f"`robotale logs delete {shlex.quote(target)}`",
        )


def _undo_after_full_disk(driver: Driver, job: _Job, full: str, error: Neo4jError) -> NoReturn:
    # Neo4j stops a database whose disk filled until it is restarted: the undo is tried, but
    # usually what was written can only be removed after a restart, with space freed.
    target, remover = job.target, f"`robotale logs delete {shlex.quote(job.target)}`"
    try:
        _undo(driver, target, job.run)
    except (Neo4jError, DriverError, OSError):
        raise ServerError(
            f"{full}: the log {target!r} was not completed; free space there, restart Neo4j "
            f"(`robotale neo4j stop`, then `robotale neo4j start`) and remove what was written "
            f"with {remover}."
        ) from error
    raise ServerError(
        f"{full}: the log {target!r} was not stored; nothing of it was kept."
    ) from error


def undo_after_failure(
    error: BaseException, undo: Callable[[], None], failed: str, remover: str
) -> NoReturn:
    """Remove what a failed write wrote (``undo``) and raise: a :class:`ServerError` saying
    so (``failed``: what failed; ``remover``: the command that removes what is left if
    ``undo`` fails too) for a server's error, else ``error`` itself (e.g. Ctrl-C)."""
    try:
        undo()
    except (Neo4jError, DriverError, OSError):
        raise ServerError(
            f"{failed} ({why(error)}) and what was written could not be removed; remove it "
            f"with {remover}."
        ) from error
    if isinstance(error, Neo4jError | DriverError | OSError):
        raise ServerError(f"{failed} ({why(error)}); nothing of it was kept.") from error
    raise error


def _answers(driver: Driver) -> bool:
    """Whether the server still answers (one attempt, no retries)."""
    try:
        driver.verify_connectivity()
        return True
    except (Neo4jError, DriverError, OSError):
        return False


def why(error: BaseException) -> str:
    """The gist of a server's or driver's error, on one line: the driver's own text spans
    lines and names connection objects."""
    if isinstance(error, Neo4jError):
        text = error.message or error.code or type(error).__name__
    elif isinstance(error, DriverError):
        text = "the connection to Neo4j was lost"
    else:
        text = str(error) or type(error).__name__
    return " ".join(str(text).split())[:300]


def _undo(driver: Driver, target: str, run: str) -> None:
    """Remove what this run wrote under ``target``: nothing if the Log node there is another
    run's (the lock makes this run the only writer of ``target`` while it lasts)."""
    owner = log_run(driver, target)
    if owner in (None, run):
        delete_log(driver, target)


def _write(driver: Driver, job: _Job, between_batches: Callable[[], None]) -> BuildSummary:
    tables, target = job.tables, job.target
    events, entities = tables.events, tables.entities
    driver.execute_query(
        cypher("ekg_log_begin"),
        log=target,
        run=job.run,
        source=job.source,
        properties=list(events.columns),
        entityTypes=entities["type"].unique().tolist(),
        database_=database(),
    )
    with ThreadPoolExecutor(max_workers=1) as beside:
        copying = beside.submit(job.copy) if job.copy is not None else None
        try:
            with _progress(tables, job.classes, target, job.progress) as bar:
                loader = Loader(driver, target, bar, between_batches)
                write_graph(loader, tables, job.classes, new_log=True, df_c=True)
                if job.objects is not None:
                    write_objects(loader, job.objects, [property_name(t) for t in job.entity_types])
            between_batches()
            finish_log(driver, target, events, job.classes)
            if copying is not None:
                copying.result()
        except BaseException:
            if copying is not None:  # the copy of a log that is not kept
                wait([copying])
                delete_copies(target)
            raise
    return summarise(target, tables, job.classes)


def finish_log(
    driver: Driver, log: str, events: pd.DataFrame, classes: Sequence[ClassTables]
) -> None:
    """Record the log's class types and summary on its Log node and mark it complete."""
    for kind in classes:
        driver.execute_query(
            cypher("ekg_log_add_class_type"), log=log, type=kind.type, database_=database()
        )
    driver.execute_query(
        cypher("ekg_log_finish"),
        log=log,
        summary={"events": len(events)} | log_values(events),
        database_=database(),
    )


def summarise(log: str, tables: GraphTables, classes: Sequence[ClassTables]) -> BuildSummary:
    """What was written of ``tables`` (DF_C: the edges computed for them)."""
    return BuildSummary(
        log=log,
        events=len(tables.events),
        entities=tables.entities.groupby("type").size().to_dict(),
        corr=len(tables.corr),
        df=tables.df.groupby("entityType").size().to_dict(),
        comm=len(tables.comm),
        df_c={c.type: len(c.df_c) for c in classes},
    )


def _progress(
    tables: GraphTables, classes: Sequence[ClassTables], target: str, shown: bool
) -> tqdm:
    rows = len(tables.events) + len(tables.entities) + len(tables.df) + len(tables.comm)
    rows += sum(len(c.classes) + len(c.df_c) + len(c.entries) for c in classes)
    return tqdm(
        total=rows, unit="row", desc=f"EKG {target}", disable=None if shown else True, leave=False
    )


def write_graph(
    loader: Loader,
    tables: GraphTables,
    classes: Sequence[ClassTables],
    *,
    new_log: bool,
    df_c: bool = False,
) -> list[np.ndarray]:
    """Entities and classes, then events with their CORR, OBSERVED, DF and COMM edges, then
    the DF and COMM edges between batches, and BEGINS edges (and with ``df_c`` the DF_C
    edges :func:`class_tables` computed). ``new_log``: nothing of the log is stored yet (an
    append finds the entities and BEGINS edges the log has). Returns the element ids of each
    key's classes, by class row."""
    entity_nodes = _write_entities(loader, tables.entities, new_log)
    class_nodes = [_write_classes(loader, c) for c in classes]
    per_event = _per_event(tables.corr, entity_nodes, len(tables.events))
    observed = _observed(classes, class_nodes, len(tables.events))
    df, comm = tables.df, tables.comm
    df_within, comm_within = within_batches(df), within_batches(comm)
    event_nodes = loader.events(
        tables.events, per_event, observed, df[df_within], comm[comm_within], tables.first
    )

    def between_events() -> None:
        _write_between(loader, df[~df_within], comm[~comm_within], event_nodes)

    def at_classes() -> None:
        for kind, nodes in zip(classes, class_nodes, strict=True):
            write_begins(loader, kind.entries, entity_nodes, nodes, new_log)
            if df_c:
                write_df_c(loader, kind, nodes)

    # the edges between events and those at entities and classes end at no node in common:
    # neither waits for the other's locks
    loader.together(between_events, at_classes)
    return class_nodes


def _write_between(
    loader: Loader, df: pd.DataFrame, comm: pd.DataFrame, event_nodes: np.ndarray
) -> None:
    """The DF and COMM edges whose two events lie in different batches."""
    for entity_type, part in df.groupby("entityType", sort=True):
        loader.run(
            "ekg_create_df",
            {
                "sources": event_nodes[part["source"]].tolist(),
                "targets": event_nodes[part["target"]].tolist(),
                "entityIds": part["entityId"].tolist(),
            },
            entityType=entity_type,
        )
    if len(comm):
        loader.run(
            "ekg_create_comm",
            {
                "sources": event_nodes[comm["source"]].tolist(),
                "targets": event_nodes[comm["target"]].tolist(),
                "msgIds": comm["msgId"].tolist(),
            },
        )


def write_df_c(loader: Loader, classes: ClassTables, nodes: np.ndarray) -> None:
    """The DF_C edges computed in ``classes`` (``nodes``: the classes' element ids)."""
    df_c = classes.df_c
    if df_c.empty:
        return
    loader.run(
        "ekg_create_df_c",
        {
            "sources": nodes[df_c["source"].to_numpy()].tolist(),
            "targets": nodes[df_c["target"].to_numpy()].tolist(),
            "entityTypes": df_c["entityType"].tolist(),
            "counts": df_c["count"].tolist(),
            "means": df_c["meanSeconds"].tolist(),
            "medians": df_c["medianSeconds"].tolist(),
        },
    )


def _write_entities(loader: Loader, entities: pd.DataFrame, new_log: bool) -> np.ndarray:
    # CREATE rather than MERGE where the log has no entity yet: no index lookup per entity
    query = "ekg_create_entities" if new_log else "ekg_merge_entities"
    nodes = np.empty(len(entities), dtype=object)
    for entity_type, part in entities.groupby("type", sort=False):
        created = loader.run(query, {"ids": part["id"].tolist()}, type=entity_type)
        nodes[part.index.to_numpy()] = created
    return nodes


def _write_classes(loader: Loader, classes: ClassTables) -> np.ndarray:
    table = classes.classes
    properties = {name: neo4j_values(table[name]) for name in classes.key}
    created = loader.run(
        "ekg_create_classes",
        {"ids": table["id"].tolist()},
        {"properties": properties},
        type=classes.type,
        key=classes.key,
    )
    return np.asarray(created, dtype=object)


def write_begins(
    loader: Loader,
    entries: pd.DataFrame,
    entity_nodes: np.ndarray,
    class_nodes: np.ndarray,
    new_log: bool,
) -> None:
    if entries.empty:
        return
    loader.run(
        "ekg_create_begins" if new_log else "ekg_merge_begins",
        {
            "entities": entity_nodes[entries["entity"].to_numpy()].tolist(),
            "classes": class_nodes[entries["class"].to_numpy()].tolist(),
            "cases": entries["cases"].tolist(),
        },
    )


def _per_event(corr: pd.DataFrame, entity_nodes: np.ndarray, events: int) -> list[list[str]]:
    """The entity element ids of each event, as one list per event."""
    ordered = corr.sort_values("event", kind="stable")
    nodes = entity_nodes[ordered["entity"].to_numpy()].tolist()
    bounds = np.searchsorted(ordered["event"].to_numpy(), np.arange(events + 1)).tolist()
    return [nodes[start:end] for start, end in itertools.pairwise(bounds)]


def _observed(
    classes: Sequence[ClassTables], class_nodes: Sequence[np.ndarray], events: int
) -> list[list[str]]:
    """The class element ids of each event (one per key), as one list per event."""
    if not classes:
        return [[] for _ in range(events)]
    columns = [nodes[c.observed] for c, nodes in zip(classes, class_nodes, strict=True)]
    ids: list[list[str]] = np.column_stack(columns).tolist()
    return ids


def _swap(driver: Driver, new: str, name: str) -> None:
    """Replace the log ``name`` by the complete log stored as ``new``."""
    try:
        delete_log(driver, name)
        with driver.session(database=database()) as session:
            for statement in statements("ekg_rename_log"):
                session.run(statement, log=new, name=name).consume()
    except (Neo4jError, DriverError, OSError) as error:
        raise ServerError(
            f"The rebuilt log is complete as {new!r} but replacing {name!r} by it failed "
            f"({error}); delete {name!r} and ingest again."
        ) from error
