"""A log that grows while its run goes on: :class:`GrowingLog`.

A live run is one case whose events keep coming. Each :meth:`GrowingLog.update` is given the
whole log as it stands now (what ``prepare`` would make of everything heard so far) and writes,
in one transaction of the append machinery (:func:`~robotale.ekg.append.write_transaction`,
under the log's write lock, held for the whole run), only what changed since the last update:
the new events with their CORR and OBSERVED edges, the DF and COMM edges that appeared or
vanished, and each event's id and position where an event heard late moved it. The stored log
therefore always equals the graph ``robotale ingest`` builds of that log, and Cypher, the
console and Discover read it while it grows.

Usually a batch only extends each entity's DF chain from its last stored event; an event
placed before stored ones (an in-progress sample, known once its activity completes, or a
message's receive heard before its send) splices into the chain instead. DF_C and BEGINS are
the whole log's (an exact median needs every duration: each pair's are kept), but written only
where they changed: the edges written last are kept in memory, an edge whose count, mean,
median or cases changed gets its new values, a new one is created and one the events no
longer give is deleted. Neo4j's work per update thus follows what the batch touched, not
how long the run has gone on (every edge was rewritten before, a growing cost over a long
run). Where events vanished (a log that shrank), every DF_C and BEGINS edge is written again.

Events are told apart across updates by a hash of their values (every property but the id,
which is a position), the n-th of equal rows matched to the n-th.

The monitor tells each update how many first events are the last update's, row for row (it
makes the run's events again from the earliest activity still open on, not whole): their
keys, element ids, places and DF edges are taken over, and only the events after them are
hashed and compared with the graph, so the update's own work follows what is new rather than
the run's length. The class tables are grown the same way
(:class:`~robotale.ekg.classgrowth.GrowingClasses`: the first events' classes and instance
edges kept, each class pair's seconds kept sorted, only the pairs the tail touches summed
again); the graph tables are still made of the whole log.
"""

from __future__ import annotations

import shlex
from contextlib import ExitStack
from dataclasses import dataclass, field
from typing import Any

import numpy as np
import pandas as pd
from neo4j import Driver, ManagedTransaction

from robotale.ekg.append import write_transaction
from robotale.ekg.build import (
    check_key_sizes,
    check_keys,
    check_log_name,
    ensure_schema,
    write_begins,
    write_df_c,
)
from robotale.ekg.classgrowth import GrowingClasses, growing_classes
from robotale.ekg.columnar import delete_copies, store_copy
from robotale.ekg.connection import database
from robotale.ekg.keys import built_keys, default_entities
from robotale.ekg.load import Loader, neo4j_values
from robotale.ekg.logs import LIVE, delete_log, log_exists, log_info
from robotale.ekg.tables import (
    ClassTables,
    GraphTables,
    graph_tables,
    log_values,
    utc_ticks,
)
from robotale.ekg.writelock import log_write_lock
from robotale.errors import InputError, LogNotFound
from robotale.queries import cypher, statements

#: what a live log's Log node records as its source: a new run of that name replaces it
LIVE_SOURCE = "robotale monitor"


#: a class edge by the element ids (and entity type) of its ends -> its values
EdgeValues = dict[tuple[str, ...], tuple[Any, ...]]


@dataclass
class _Stored:
    """What the graph holds of the log, by event key (see :func:`event_keys`)."""

    nodes: dict[str, str] = field(default_factory=dict)  # event key -> element id
    placed: dict[str, tuple[str, int]] = field(default_factory=dict)  # key -> (id, order)
    #: the log's events in order: their keys, hashes and element ids, and how many events
    #: share each hash; the column types of the event table they were made of
    keys: EventKeys = field(default_factory=lambda: EventKeys())
    event_nodes: np.ndarray = field(default_factory=lambda: np.empty(0, dtype=object))
    dtypes: tuple[str, ...] = ()
    entities: dict[tuple[str, str], str] = field(default_factory=dict)  # (type, id) -> element
    classes: dict[tuple[str, str], str] = field(default_factory=dict)  # (type, id) -> element
    #: the DF edges (their ends' keys, type, entity id), ordered by the later position of
    #: their two ends, and those positions: the edges touching the events from a position
    #: on are a tail of the list
    df: list[tuple[str, str, str, str]] = field(default_factory=list)
    df_last: np.ndarray = field(default_factory=lambda: np.empty(0, dtype=np.int64))
    comm: set[tuple[str, str, str]] = field(default_factory=set)  # send, receive keys, msg id
    #: (source class, target class, entity type) element ids -> (count, mean, median seconds)
    df_c: EdgeValues = field(default_factory=dict)
    #: (entity, class) element ids -> (cases,)
    begins: EdgeValues = field(default_factory=dict)


@dataclass
class _Change:
    """One update: the log's tables now, their event keys, the store before it, and how
    many of the first events are the last update's (``same``: the same values, ids and
    places; only the events after them are compared with what the graph holds)."""

    tables: GraphTables
    classes: list[ClassTables]
    keys: EventKeys
    before: _Stored
    same: int = 0
    after: _Stored = field(default_factory=_Stored)
    #: what the transaction changes of the store's dicts by event key, applied once it
    #: committed (:meth:`commit`): a dict of the run's length is not copied each update,
    #: and a transaction tried again finds the store as it was
    replaced: list[tuple[dict[str, Any], list[str], dict[str, Any]]] = field(default_factory=list)

    def commit(self) -> _Stored:
        """The store after the update: each dict without the keys gone, with the new values."""
        for held, gone, new in self.replaced:
            for key in gone:
                del held[key]
            held.update(new)
        return self.after

    @property
    def new(self) -> np.ndarray:
        """Positions of the events the graph does not hold yet (none of the first ``same``)."""
        tail = self.keys.keys[self.same :].tolist()
        return self.same + np.flatnonzero([key not in self.before.nodes for key in tail])

    @property
    def tail(self) -> dict[str, int]:
        """The positions of the events after the first ``same``, by key."""
        return {key: self.same + k for k, key in enumerate(self.keys.keys[self.same :].tolist())}

    def position(self, key: str, tail: dict[str, int]) -> int:
        """Where the event ``key`` is now: among the ``tail`` or, before it, where it was."""
        at = tail.get(key)
        return self.before.placed[key][1] if at is None else at

    @property
    def gone(self) -> list[str]:
        """The keys of the events the graph holds and the log no longer has."""
        now = set(self.keys.keys[self.same :].tolist())
        return sorted(k for k in self.before.keys.keys[self.same :].tolist() if k not in now)


class GrowingLog:
    """The live log ``name``: refused when a log of that name is stored that no monitor
    wrote; an earlier live log of that name is replaced. Holds the log's write lock from
    here until :meth:`close`."""

    def __init__(self, driver: Driver, name: str) -> None:
        check_log_name(name)
        self.driver, self.name = driver, name
        ensure_schema(driver)
        self._stack = ExitStack()
        self.run = self._stack.enter_context(log_write_lock(driver, name, "monitoring"))
        try:
            self._clear_earlier()
        except BaseException:
            self._stack.close()
            raise
        self.stored = _Stored()
        self.log: pd.DataFrame | None = None
        self.begun = False  # the Log node is written
        self.summary: dict[str, Any] = {}
        self.types: list[str] = []
        self.keys: list[list[str]] = []
        #: what the events of the last update gave each key's class tables
        self.classes: list[GrowingClasses] = []
        #: events whose keys and places updates took over from the last (for tests)
        self.reused = 0
        #: instance DF edges the class tables took over from the last update (for tests)
        self.classes_reused = 0

    @property
    def events(self) -> int:
        """How many events the graph holds."""
        return len(self.stored.nodes)

    def _clear_earlier(self) -> None:
        if not log_exists(self.driver, self.name):
            return
        try:
            source = log_info(self.driver, self.name)["source"]
        except LogNotFound:  # events without a Log node: a failed ingest's
            source = None
        if source != LIVE_SOURCE:
            raise InputError(
                f"A log named {self.name!r} is stored in Neo4j and is not a live run's: "
                "give the monitor another --log, or remove that log with "
                f"`robotale logs delete {shlex.quote(self.name)}`."
            )
        delete_log(self.driver, self.name)
        delete_copies(self.name)

    def update(self, log: pd.DataFrame, same: int = 0) -> int:
        """Make the stored log the graph of ``log`` (a canonical event log: the whole run so
        far); returns how many events were new. Nothing is written when nothing changed.

        ``same``: how many of the first rows of ``log`` are those of the log of the last
        update, row for row (what :class:`~robotale.results.live.LiveEvents` keeps): their
        keys and places are taken over and only the rows after them compared with the graph,
        so the work in Python follows the rows made again, not the run's length. Taken as 0
        when the event table's column types changed or a later row is older than one of them
        (their DF edges could then change)."""
        if log.empty:
            return 0
        if not self.types:
            self.types = default_entities(log.columns)
            self.keys = [key.split(",") for key in built_keys(self.types)]
        tables = graph_tables(log, self.types)
        check_keys(tables.events, self.keys)
        check_key_sizes(tables, self.keys)
        same = _same(tables.events, self.stored, same)
        grown = [kept.grown(tables, same) for kept in self.classes or growing_classes(self.keys)]
        classes = [made for _, made in grown]
        keys = self.stored.keys.grown(tables.events, same)
        change = _Change(tables, classes, keys, self.stored, same)
        self.reused += same
        self.classes_reused += sum(int(np.searchsorted(kept.last, same)) for kept in self.classes)
        new = len(change.new)
        if not new and keys.keys.tolist() == self.stored.keys.keys.tolist():
            return 0  # the same events in the same places: their edges are the same too
        if not self.begun:
            self._begin(tables, classes)
            self.begun = True
        summary = {"events": len(tables.events)} | log_values(tables.events)
        write_transaction(self.driver, self.name, _write, self.name, change, summary)
        self.stored, self.log, self.summary = change.commit(), log, summary
        self.classes = [kept for kept, _ in grown]
        return new

    def _begin(self, tables: GraphTables, classes: list[ClassTables]) -> None:
        self.driver.execute_query(
            cypher("ekg_live_begin"),
            log=self.name,
            run=self.run,
            source=LIVE_SOURCE,
            status=LIVE,
            properties=list(tables.events.columns),
            entityTypes=list(self.types),
            classTypes=[kind.type for kind in classes],
            database_=database(),
        )

    def finish(self) -> None:
        """The run ended: the log is complete (and gets its columnar copy, as an ingest's)."""
        if self.log is not None:
            self.driver.execute_query(
                cypher("ekg_log_finish"),
                log=self.name,
                summary=self.summary,
                database_=database(),
            )
            store_copy(self.driver, self.name, self.log)
        self.close()

    def close(self) -> None:
        """Give the write lock back (a log left ``live`` shows as interrupted)."""
        self._stack.close()


@dataclass(frozen=True)
class EventKeys:
    """One text per event that stays the same while the log grows: a 64-bit hash of its
    values but the id (a position), and how many equal events come before it. Texts of the
    values themselves cost ten times more; two different events share a hash with a chance
    of about n²/2⁶⁵ (1 in 4·10⁹ for 100,000 events). With the hashes, and how many events
    share each, so a grown log's keys are made of its new rows only."""

    keys: np.ndarray = field(default_factory=lambda: np.empty(0, dtype=object))
    hashes: np.ndarray = field(default_factory=lambda: np.empty(0, dtype=np.uint64))
    counts: dict[int, int] = field(default_factory=dict)

    def grown(self, events: pd.DataFrame, same: int) -> EventKeys:
        """The keys of ``events``, whose first ``same`` rows are those these keys are of."""
        counts = dict(self.counts)
        for h in self.hashes[same:].tolist():  # the rows after them: gone or made again
            counts[h] -= 1
        tail = pd.util.hash_pandas_object(events.iloc[same:].drop(columns="id"), index=False)
        hashes = tail.to_numpy().tolist()
        keys = []
        for h in hashes:
            seen = counts.get(h, 0)
            keys.append(f"{h:016x}#{seen}")
            counts[h] = seen + 1
        return EventKeys(
            np.concatenate([self.keys[:same], np.array(keys, dtype=object)]),
            np.concatenate([self.hashes[:same], np.array(hashes, dtype=np.uint64)]),
            counts,
        )


def event_keys(events: pd.DataFrame) -> np.ndarray:
    """The keys of ``events`` (:class:`EventKeys`) made of all of them."""
    return EventKeys().grown(events, 0).keys


def _same(events: pd.DataFrame, stored: _Stored, same: int) -> int:
    """``same`` (how many first rows of ``events`` are the last update's, as the caller
    says), or 0 where taking them over could be wrong: the column types changed (a value's
    hash depends on its column's type), or a later event is older than one of them (it
    would fall between them in an entity's DF chain)."""
    same = min(same, len(events), len(stored.keys.keys))
    if same <= 0 or _dtypes(events) != stored.dtypes:
        return 0
    ticks = utc_ticks(events)
    if same < len(events) and ticks[same:].min() < ticks[:same].max():
        return 0
    return same


def _dtypes(events: pd.DataFrame) -> tuple[str, ...]:
    return tuple(f"{name}:{dtype}" for name, dtype in events.dtypes.items())


def _write(
    tx: ManagedTransaction,
    name: str,
    change: _Change,
    summary: dict[str, Any],
    between_batches: Any,
) -> None:
    """The transaction of one update; fills ``change.after`` with what the graph then holds."""
    loader = Loader(None, name, None, between_batches, tx=tx)
    tables, keys, before = change.tables, change.keys.keys, change.before
    after = _Stored(entities=dict(before.entities), classes=dict(before.classes))
    after.keys, after.dtypes = change.keys, _dtypes(tables.events)
    gone = change.gone
    if gone:
        deleted = [before.nodes[key] for key in gone]
        for statement in statements("ekg_live_delete_events"):
            tx.run(statement, log=name, nodes=deleted).consume()
        after.entities, after.classes = {}, {}  # an entity may have gone with its events
        entity_nodes = _merged(loader, tables.entities, {})
        class_nodes = [_merged_classes(loader, kind, {}) for kind in change.classes]
    else:
        entity_nodes = _merged(loader, tables.entities, after.entities)
        class_nodes = [_merged_classes(loader, kind, after.classes) for kind in change.classes]
    for (kind, entity), node in zip(
        tables.entities.itertuples(index=False), entity_nodes, strict=True
    ):
        after.entities[(str(kind), str(entity))] = node
    for kind, nodes in zip(change.classes, class_nodes, strict=True):
        ids = kind.classes["id"].astype(str).tolist()
        after.classes |= {(kind.type, c): n for c, n in zip(ids, nodes, strict=True)}
    event_nodes = _events(loader, change, entity_nodes, class_nodes)
    tail = change.tail
    # the first ``same`` events' keys and element ids stay; the rest are the tail's
    after.event_nodes = event_nodes
    fresh = {key: event_nodes[at] for key, at in tail.items()}
    # the events after the first ``same`` of the last update's replaced by the tail's
    out = before.keys.keys[change.same :].tolist()
    places = _renumber(tx, name, change, tail, event_nodes)
    after.nodes, after.placed = before.nodes, before.placed
    change.replaced = [(before.nodes, out, fresh), (before.placed, out, places)]
    after.df, after.df_last = _edges(loader, tx, name, change, tail, event_nodes)
    after.comm = _comm(loader, tables, keys, event_nodes, before.comm)
    for kind, nodes in zip(change.classes, class_nodes, strict=True):
        between_batches()
        if gone:  # classes and entities may have gone and come again: write every edge
            tx.run(cypher("ekg_ocel_delete_df_c"), log=name, type=kind.type).consume()
            write_df_c(loader, kind, nodes)
            tx.run(cypher("ekg_live_delete_begins"), log=name, type=kind.type).consume()
            write_begins(loader, kind.entries, entity_nodes, nodes, new_log=True)
        after.df_c |= df_c_edges(kind, nodes)
        after.begins |= begins_edges(kind, entity_nodes, nodes)
    if not gone:
        _write_changed(loader, tx, name, _DF_C, before.df_c, after.df_c)
        _write_changed(loader, tx, name, _BEGINS, before.begins, after.begins)
    tx.run(cypher("ekg_log_summary"), log=name, summary=summary).consume()
    change.after = after


def _merged(
    loader: Loader, entities: pd.DataFrame, known: dict[tuple[str, str], str]
) -> np.ndarray:
    """The element ids of ``entities`` (rows: type, id), those not ``known`` merged now."""
    nodes = np.array(
        [known.get((str(t), str(i))) for t, i in entities.itertuples(index=False)], dtype=object
    )
    missing = entities[pd.isna(nodes)]
    for entity_type, part in missing.groupby("type", sort=False):
        created = loader.run("ekg_merge_entities", {"ids": part["id"].tolist()}, type=entity_type)
        nodes[entities.index.get_indexer(part.index)] = created
    return nodes


def _merged_classes(
    loader: Loader, kind: ClassTables, known: dict[tuple[str, str], str]
) -> np.ndarray:
    """The element ids of the classes of ``kind``, those not ``known`` merged now."""
    table = kind.classes
    nodes = np.array([known.get((kind.type, str(c))) for c in table["id"]], dtype=object)
    missing = table[pd.isna(nodes)]
    if len(missing):
        created = loader.run(
            "ekg_create_classes",
            {"ids": missing["id"].tolist()},
            {"properties": {k: neo4j_values(missing[k]) for k in kind.key}},
            type=kind.type,
            key=kind.key,
        )
        nodes[np.flatnonzero(pd.isna(nodes))] = created
    return nodes


def _events(
    loader: Loader,
    change: _Change,
    entity_nodes: np.ndarray,
    class_nodes: list[np.ndarray],
) -> np.ndarray:
    """The element ids of every event of the log, the new ones created now with their CORR
    and OBSERVED edges, under ids of their own until :func:`_renumber` places them."""
    tables, keys, before, same = change.tables, change.keys.keys, change.before, change.same
    tail = [before.nodes.get(key) for key in keys[same:].tolist()]
    nodes = np.concatenate([before.event_nodes[:same], np.array(tail, dtype=object)])
    new = change.new
    if not len(new):
        return nodes
    corr = tables.corr[np.isin(tables.corr["event"].to_numpy(), new)]
    per_event: dict[int, list[str]] = {int(i): [] for i in new}
    for event, entity in corr.itertuples(index=False):
        per_event[int(event)].append(entity_nodes[int(entity)])
    observed = [
        [
            nodes_of[kind.observed[i]]
            for kind, nodes_of in zip(change.classes, class_nodes, strict=True)
        ]
        for i in new.tolist()
    ]
    fresh = tables.events.iloc[new].assign(id=[f"{_PLACING}{key}" for key in keys[new]])
    empty = pd.DataFrame(
        {"source": [], "target": [], "entityType": [], "entityId": [], "msgId": []}
    )
    created = loader.events(
        fresh.reset_index(drop=True),
        [per_event[int(i)] for i in new],
        observed,
        empty.astype({"source": np.int64, "target": np.int64}),
        empty.astype({"source": np.int64, "target": np.int64}),
    )
    nodes[new] = created
    return nodes


#: the prefix of the id an event has while an update places it (no log's id starts so)
_PLACING = "\x00placing "


def _renumber(
    tx: ManagedTransaction,
    name: str,
    change: _Change,
    tail: dict[str, int],
    nodes: np.ndarray,
) -> dict[str, tuple[str, int]]:
    """Give every event whose id or position changed (and every new one) its own; moved
    events first get ids of their own, so no two events share an id on the way. The first
    ``change.same`` events keep theirs."""
    before, keys, same = change.before, change.keys.keys, change.same
    ids = change.tables.events["id"].iloc[same:].astype(str).tolist()
    places = {key: (ids[at - same], at) for key, at in tail.items()}
    moved = [at for key, at in tail.items() if before.placed.get(key) != places[key]]
    if not moved:
        return places
    stored = [k for k in moved if keys[k] in before.placed]
    query = cypher("ekg_live_renumber")
    if stored:
        tx.run(
            query,
            log=name,
            nodes=nodes[stored].tolist(),
            ids=[f"{_PLACING}{keys[k]}" for k in stored],
            orders=stored,
        ).consume()
    tx.run(
        query,
        log=name,
        nodes=nodes[moved].tolist(),
        ids=[places[keys[k]][0] for k in moved],
        orders=moved,
    ).consume()
    return places


def _edges(
    loader: Loader,
    tx: ManagedTransaction,
    name: str,
    change: _Change,
    tail: dict[str, int],
    nodes: np.ndarray,
) -> tuple[list[tuple[str, str, str, str]], np.ndarray]:
    """The DF edges of the log now (see :attr:`_Stored.df`): those that vanished deleted, the
    new ones created. Only the edges touching the events after the first ``change.same``
    are compared: the edges between those events are the last update's (no later event is
    older than they are, so none falls between them in a chain)."""
    df, keys, before, same = change.tables.df, change.keys.keys, change.before, change.same
    sources, targets = df["source"].to_numpy(), df["target"].to_numpy()
    last = np.maximum(sources, targets)
    touching = np.flatnonzero(last >= same)
    touching = touching[np.argsort(last[touching], kind="stable")]
    now = list(
        zip(
            keys[sources[touching]].tolist(),
            keys[targets[touching]].tolist(),
            df["entityType"].take(touching).astype(str).tolist(),
            df["entityId"].take(touching).astype(str).tolist(),
            strict=True,
        )
    )
    first = int(np.searchsorted(before.df_last, same))
    held = set(before.df[first:])
    fresh = set(now)
    # the edges of deleted events went with them
    stale = [e for e in held - fresh if _holds(change, tail, e[0]) and _holds(change, tail, e[1])]
    if stale:
        tx.run(
            cypher("ekg_live_delete_df"),
            log=name,
            sources=[nodes[change.position(e[0], tail)] for e in stale],
            targets=[nodes[change.position(e[1], tail)] for e in stale],
            entityTypes=[e[2] for e in stale],
            entityIds=[e[3] for e in stale],
        ).consume()
    added = sorted(fresh - held)
    for entity_type in sorted({e[2] for e in added}):
        part = [e for e in added if e[2] == entity_type]
        loader.run(
            "ekg_create_df",
            {
                "sources": [nodes[change.position(e[0], tail)] for e in part],
                "targets": [nodes[change.position(e[1], tail)] for e in part],
                "entityIds": [e[3] for e in part],
            },
            entityType=entity_type,
        )
    return before.df[:first] + now, np.concatenate([before.df_last[:first], last[touching]])


def _holds(change: _Change, tail: dict[str, int], key: str) -> bool:
    """Whether the log now has the event ``key`` (one of the first ``same``, or the tail's)."""
    if key in tail:
        return True
    place = change.before.placed.get(key)
    return place is not None and place[1] < change.same


def _comm(
    loader: Loader,
    tables: GraphTables,
    keys: np.ndarray,
    nodes: np.ndarray,
    before: set[tuple[str, str, str]],
) -> set[tuple[str, str, str]]:
    """The COMM edges of the log now, the new ones created (a COMM edge vanishes only with
    one of its events)."""
    comm = tables.comm
    sources = comm["source"].to_numpy(dtype=np.int64)
    targets = comm["target"].to_numpy(dtype=np.int64)
    now = set(
        zip(
            keys[sources].tolist(),
            keys[targets].tolist(),
            comm["msgId"].astype(str).tolist(),
            strict=True,
        )
    )
    added = sorted(now - before)
    if added:
        at = {key: k for k, key in enumerate(keys.tolist())}
        loader.run(
            "ekg_create_comm",
            {
                "sources": [nodes[at[e[0]]] for e in added],
                "targets": [nodes[at[e[1]]] for e in added],
                "msgIds": [e[2] for e in added],
            },
        )
    return now


def df_c_edges(kind: ClassTables, nodes: np.ndarray) -> EdgeValues:
    """The DF_C edges of ``kind`` by their ends' element ids and entity type, with their
    count, mean and median seconds (what :func:`~robotale.ekg.build.write_df_c` writes)."""
    df_c = kind.df_c
    ends = zip(
        nodes[df_c["source"].to_numpy()].tolist(),
        nodes[df_c["target"].to_numpy()].tolist(),
        df_c["entityType"].astype(str).tolist(),
        strict=True,
    )
    values = zip(
        df_c["count"].astype(int).tolist(),
        df_c["meanSeconds"].astype(float).tolist(),
        df_c["medianSeconds"].astype(float).tolist(),
        strict=True,
    )
    return dict(zip(ends, values, strict=True))


def begins_edges(kind: ClassTables, entity_nodes: np.ndarray, nodes: np.ndarray) -> EdgeValues:
    """The BEGINS edges of ``kind`` by their ends' element ids, with their cases (a 1-tuple)."""
    entries = kind.entries
    ends = zip(
        entity_nodes[entries["entity"].to_numpy()].tolist(),
        nodes[entries["class"].to_numpy()].tolist(),
        strict=True,
    )
    cases = ((count,) for count in entries["cases"].astype(int).tolist())
    return dict(zip(ends, cases, strict=True))


@dataclass(frozen=True)
class _ClassEdges:
    """One kind of class edge the live log writes where it changed: its queries (each takes
    the ends, and the set and create queries the values, as parallel lists) and the names of
    those lists."""

    delete: str
    update: str
    create: str
    ends: tuple[str, ...]
    values: tuple[str, ...]


_DF_C = _ClassEdges(
    "ekg_live_delete_df_c_edges",
    "ekg_live_set_df_c",
    "ekg_create_df_c",
    ("sources", "targets", "entityTypes"),
    ("counts", "means", "medians"),
)
_BEGINS = _ClassEdges(
    "ekg_live_delete_begins_edges",
    "ekg_live_set_begins",
    "ekg_create_begins",
    ("entities", "classes"),
    ("cases",),
)


def _write_changed(
    loader: Loader,
    tx: ManagedTransaction,
    name: str,
    kind: _ClassEdges,
    before: EdgeValues,
    now: EdgeValues,
) -> None:
    """Make the graph's ``kind`` edges ``now`` from ``before``, touching only those that
    differ: the stale deleted, the changed given their values, the new created."""
    stale = sorted(set(before) - set(now))
    if stale:
        tx.run(cypher(kind.delete), {"log": name, **_columns(kind.ends, stale)}).consume()
    changed = sorted(e for e in now if e in before and before[e] != now[e])
    added = sorted(e for e in now if e not in before)
    for query, edges in ((kind.update, changed), (kind.create, added)):
        if edges:
            values = _columns(kind.values, [now[e] for e in edges])
            loader.run(query, {**_columns(kind.ends, edges), **values})


def _columns(names: tuple[str, ...], rows: list[tuple[Any, ...]]) -> dict[str, list[Any]]:
    """``rows`` as one list per column, named ``names``: a query's parallel parameters."""
    return {column: [row[i] for row in rows] for i, column in enumerate(names)}
