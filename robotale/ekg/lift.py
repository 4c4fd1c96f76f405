"""The edges an aggregation step lifts, computed in memory from the log's columnar copy.

The CORR, DF and COMM edges of a log are derived from its event table (the columnar copy,
:func:`robotale.ekg.columnar.stored_table`) as the build derived them
(:func:`robotale.ekg.tables.graph_tables`), instead of being read back from Neo4j. Nodes are
integer codes: the events by their position in the log, then the entities by their row in
the entity table (an entity no event names gets a code when a step meets it), then the
aggregates. Which aggregate holds each node is kept per code. A step's edges are found with
numpy, their ends mapped to what stands for them at this level (the aggregate holding the
node, else the node), counted per pair, kind and entity type with pandas. The aggregates'
element ids are known from their creation; those of the events and entities a lifted edge
reaches are read once per run, only those, all in one query (looking each up by its key as
an edge is written costs Neo4j more than the edge itself).

The rules are those of a step lifted in Cypher: an edge from a member becomes an edge from
its aggregate; an edge into a member from a node no aggregate of the same step holds becomes
an edge into its aggregate (so an edge between two aggregates of one step is written once).
Each lifted edge belongs to the later step of its two ends (a node no step holds counts as
step 0), so :meth:`LogEdges.lift` takes, for a step, only the edges whose other end stands
at a step no later than it.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
import pandas as pd
from neo4j import Driver

from robotale.ekg.columnar import Build, stored_table
from robotale.ekg.connection import read_autocommit
from robotale.ekg.tables import GraphTables, graph_tables
from robotale.errors import InputError
from robotale.queries import cypher

#: a node no aggregate holds
FREE = -1
#: the kinds of edge a step lifts, in the order of their codes in :attr:`LogEdges.kinds`
KINDS = np.asarray(["CORR", "DF", "COMM"], dtype=object)


@dataclass
class LogEdges:
    """The log's liftable edges and who holds each node, by integer codes."""

    events: pd.DataFrame  # the event table (Event property names); row = position = code
    types: np.ndarray  # per code: an entity's type; None for events and aggregates
    keys: np.ndarray  # per code: the node's id (events, entities) or the aggregate's id
    element_ids: np.ndarray  # per code: an aggregate's element id; None for the others
    stored: np.ndarray  # per code: an event's or entity's element id once read; else None
    kinds: np.ndarray  # per edge: its kind's position in :data:`KINDS`
    sources: np.ndarray  # codes
    targets: np.ndarray
    entity_types: np.ndarray  # per edge: a DF edge's entity type's position in ``type_names``
    type_names: np.ndarray  # None (the edges but DF), then the DF edges' entity types
    holder: np.ndarray  # per code: the code of the aggregate holding it, or FREE
    levels: np.ndarray  # per code: an aggregate's step; 0 for events and entities
    corr: pd.DataFrame  # ``event``, ``entity`` (codes): what each event is correlated to
    #: the lifted edges of every step at the level the nodes are held now, with their
    #: ``step``; None until asked for, and again when a node's holder changes
    owned: pd.DataFrame | None = None

    @classmethod
    def of_log(
        cls, driver: Driver, log: str, entity_types: Sequence[str], build: Build | None = None
    ) -> LogEdges:
        """The edges of the stored log ``log`` built with ``entity_types`` (``build``: its
        current build, when the caller has read it)."""
        table = stored_table(driver, log, build=build)
        return cls.of_tables(graph_tables(table, list(entity_types), lifting=True))

    @classmethod
    def of_tables(cls, tables: GraphTables) -> LogEdges:
        events, entities = tables.events, tables.entities
        count = len(events)
        corr = tables.corr["entity"].to_numpy() + count
        df, comm = tables.df, tables.comm
        # kinds and entity types as small integers: millions of edges as Python strings cost
        # more to make, and to group, than the rest of the lifting (tables derived for
        # lifting name a DF edge's entity by its row: its type's code is looked up)
        if "entity" in df.columns:
            codes, names = pd.factorize(entities["type"])
            df_types = codes[df["entity"].to_numpy()]
        else:
            df_types, names = pd.factorize(df["entityType"])
        frames = [
            (tables.corr["event"].to_numpy(), corr, np.zeros(len(corr), np.int64)),
            (df["source"].to_numpy(), df["target"].to_numpy(), df_types.astype(np.int64) + 1),
            (comm["source"].to_numpy(), comm["target"].to_numpy(), np.zeros(len(comm), np.int64)),
        ]
        codes = count + len(entities)
        return cls(
            events=events,
            types=np.concatenate(
                [np.full(count, None, object), entities["type"].astype(object).to_numpy()]
            ),
            keys=np.concatenate(
                [events["id"].astype(object).to_numpy(), entities["id"].astype(object).to_numpy()]
            ),
            element_ids=np.full(codes, None, dtype=object),
            stored=np.full(codes, None, dtype=object),
            kinds=np.concatenate([np.full(len(f[0]), k, np.int64) for k, f in enumerate(frames)]),
            sources=np.concatenate([np.asarray(f[0], np.int64) for f in frames]),
            targets=np.concatenate([np.asarray(f[1], np.int64) for f in frames]),
            entity_types=np.concatenate([f[2] for f in frames]),
            type_names=np.asarray([None, *np.asarray(names, dtype=object)], dtype=object),
            holder=np.full(codes, FREE, dtype=np.int64),
            levels=np.zeros(codes, dtype=np.int64),
            corr=pd.DataFrame({"event": tables.corr["event"].to_numpy(), "entity": corr}),
        )

    # -- codes ---------------------------------------------------------------------------

    def _append(
        self, types: np.ndarray, keys: np.ndarray, element_ids: np.ndarray, level: int = 0
    ) -> np.ndarray:
        first = len(self.keys)
        self.types = np.concatenate([self.types, types])
        self.keys = np.concatenate([self.keys, keys])
        self.element_ids = np.concatenate([self.element_ids, element_ids])
        self.stored = np.concatenate([self.stored, np.full(len(keys), None, dtype=object)])
        self.holder = np.concatenate([self.holder, np.full(len(keys), FREE, dtype=np.int64)])
        self.levels = np.concatenate([self.levels, np.full(len(keys), level, dtype=np.int64)])
        return np.arange(first, first + len(keys))

    def event_codes(self, ids: Sequence[str]) -> np.ndarray:
        """The codes of events by id (the positions of the events with those ids)."""
        found: np.ndarray = pd.Index(self.events["id"].astype(object)).get_indexer(
            pd.Index(list(ids), dtype=object)
        )
        if (found < 0).any():
            missing = np.asarray(ids, dtype=object)[found < 0][0]
            raise InputError(
                f"An aggregation step of this log holds the event {missing!r}, which the log "
                "no longer has: undo its steps (robotale aggregate LOG --undo 1) and run them "
                "again."
            )
        return found

    def entity_codes(self, kind: str, ids: Sequence[str]) -> np.ndarray:
        """The codes of the entities of type ``kind`` by id (new codes for entities that no
        event names)."""
        wanted: np.ndarray = np.asarray(list(ids), dtype=object)
        mine = np.flatnonzero(self.types == kind)
        index = pd.Index(self.keys[mine], dtype=object)
        at = (
            index.get_indexer(pd.Index(wanted, dtype=object))
            if len(index)
            else np.full(len(wanted), -1)
        )
        found = np.where(at >= 0, mine[np.maximum(at, 0)], -1)
        new = found < 0
        if new.any():
            unique, positions = np.unique(wanted[new], return_inverse=True)
            codes = self._append(
                np.full(len(unique), kind, object), unique, np.full(len(unique), None, object)
            )
            found[new] = codes[positions]
        return found

    # -- aggregates ------------------------------------------------------------------------

    def hold(
        self,
        nodes: np.ndarray,
        aggregates: Sequence[str],
        element_ids: Sequence[str | None],
        step: int,
    ) -> np.ndarray:
        """Record that each of ``nodes`` (codes) is held by the aggregate of step ``step`` of
        the same position (``aggregates``: their ids, ``element_ids`` theirs, None while it is
        not written yet); returns the aggregates' codes."""
        names, first, positions = np.unique(
            np.asarray(list(aggregates), dtype=object), return_index=True, return_inverse=True
        )
        elements = np.asarray(list(element_ids), dtype=object)[first]
        codes = self._append(np.full(len(names), None, object), names, elements, step)
        self.holder[nodes] = codes[positions]
        self.owned = None
        return codes[positions]

    def aggregates_of(self, step: int) -> np.ndarray:
        """The codes of the aggregates of step ``step``."""
        return np.flatnonzero(self.levels == step)

    def written(self, ids: Sequence[str], element_ids: Sequence[str], step: int) -> None:
        """The aggregates of step ``step`` with ``ids`` were created with ``element_ids``."""
        mine = self.aggregates_of(step)
        at = pd.Index(self.keys[mine], dtype=object).get_indexer(pd.Index(list(ids), dtype=object))
        self.element_ids[mine[at]] = np.asarray(list(element_ids), dtype=object)

    def release(self, step: int) -> np.ndarray:
        """Forget the aggregates of steps ``step`` and later (undone, or never written): their
        members are free again; returns those members' codes."""
        held = self.holder >= 0
        freed = np.flatnonzero(held & (self.levels[np.maximum(self.holder, 0)] >= step))
        self.holder[freed] = FREE
        self.owned = None
        return freed

    def ends(self, driver: Driver, log: str, codes: np.ndarray) -> np.ndarray:
        """The element ids of ``codes``: an aggregate's as created; the events' and entities'
        read from Neo4j the first time one of them is asked for, together with every other
        event and entity the lifted edges of any step reach (one read per run)."""
        unread = codes[pd.isna(self.element_ids[codes]) & pd.isna(self.stored[codes])]
        if unread.size:
            self._read_stored(driver, log, np.union1d(unread, self._free_ends()))
        ends: np.ndarray = np.where(
            pd.isna(self.element_ids[codes]), self.stored[codes], self.element_ids[codes]
        )
        if pd.isna(ends).any():  # an edge to it would be dropped without a word
            missing = self.keys[codes[pd.isna(ends)][0]]
            raise InputError(
                f"The log {log!r} in Neo4j has no node {missing!r}, which its columnar copy "
                "names: ingest the log again (robotale ingest ... --replace)."
            )
        return ends

    def _free_ends(self) -> np.ndarray:
        """The events and entities (no aggregates) that the lifted edges of every step at this
        level reach and whose element ids are not read yet; none before :meth:`lift_level`."""
        if self.owned is None:
            return np.empty(0, dtype=np.int64)
        reached = np.union1d(self.owned["source"].to_numpy(), self.owned["target"].to_numpy())
        found: np.ndarray = reached[(self.levels[reached] == 0) & pd.isna(self.stored[reached])]
        return found

    def _read_stored(self, driver: Driver, log: str, codes: np.ndarray) -> None:
        """Read the element ids of the events and entities ``codes`` (by their keys, one
        query) into :attr:`stored`."""
        events = codes[codes < len(self.events)]
        entities = codes[codes >= len(self.events)]
        parameters = {
            "log": log,
            "events": [str(k) for k in self.keys[events]],
            "entities": [str(k) for k in self.keys[entities]],
            "types": [str(t) for t in self.types[entities]],
        }
        # one round trip: no commit of its own for a read
        row = read_autocommit(driver, cypher("aggr_element_ids"), parameters)[0]
        for nodes, found, elements in (
            (events, row["eventsFound"], row["eventElements"]),
            (entities, row["entitiesFound"], row["entityElements"]),
        ):
            self.stored[nodes[np.asarray(found, dtype=np.int64)]] = np.asarray(elements, object)

    def standing(self, codes: np.ndarray) -> np.ndarray:
        """What stands for each code at this level: the id of the aggregate holding it, else
        its own id."""
        held = self.holder[codes]
        found: np.ndarray = np.where(held >= 0, self.keys[np.maximum(held, 0)], self.keys[codes])
        return found

    def free_events(self) -> np.ndarray:
        """The positions of the events no aggregate holds."""
        return np.flatnonzero(self.holder[: len(self.events)] == FREE)

    def lift_level(self, step: int) -> pd.DataFrame:
        """The lifted edges step ``step`` owns (as :meth:`lift` of its aggregates ``upto`` it
        gives them): each edge belongs to the later step of the two ends standing for its
        nodes, so every step's are found in one pass over the log's edges, kept until a
        node's holder changes."""
        if self.owned is None:
            lifted = self._lifted(np.ones(len(self.sources), dtype=bool))
            ends = (
                self.levels[lifted["source"].to_numpy()],
                self.levels[lifted["target"].to_numpy()],
            )
            self.owned = lifted.assign(step=np.maximum(*ends))
        owned = self.owned[self.owned["step"].to_numpy() == step]
        return owned.drop(columns="step").reset_index(drop=True)

    def lift(
        self, step: np.ndarray, upto: int | None = None, others: np.ndarray | None = None
    ) -> pd.DataFrame:
        """The lifted edges of the step whose aggregates are the codes ``step``: ``kind``,
        ``source``, ``target`` (codes), ``entityType`` (None but for DF) and ``count``. Ends
        stand for what holds them now; with ``upto``, only the edges whose other end stands
        at step ``upto`` or earlier (a free node: 0), the later step's edges being its own;
        with ``others`` (codes), only those whose other end is one of them."""
        in_step = np.zeros(len(self.keys), dtype=bool)
        in_step[step] = True
        standing = np.where(self.holder >= 0, self.holder, np.arange(len(self.keys)))
        source, target = standing[self.sources], standing[self.targets]
        other = np.ones(len(self.keys), dtype=bool)
        if upto is not None:
            other &= self.levels <= upto
        if others is not None:
            wanted = np.zeros(len(self.keys), dtype=bool)
            wanted[others] = True
            other &= wanted
        # out of a member; or into one from a node that no aggregate of this step holds
        chosen = (in_step[source] & other[target]) | (
            in_step[target] & ~in_step[source] & other[source]
        )
        return self._lifted(chosen, source, target)

    def _lifted(
        self,
        chosen: np.ndarray,
        source: np.ndarray | None = None,
        target: np.ndarray | None = None,
    ) -> pd.DataFrame:
        """The ``chosen`` edges (a mask) between what stands for their ends (``source``,
        ``target``: codes per edge, by default what holds each end now) counted per pair,
        kind and entity type; an edge between two free nodes is no lifted edge."""
        if source is None or target is None:
            standing = np.where(self.holder >= 0, self.holder, np.arange(len(self.keys)))
            source, target = standing[self.sources], standing[self.targets]
            chosen = chosen & ((self.holder[self.sources] >= 0) | (self.holder[self.targets] >= 0))
        # one integer per (source, target, entity type, kind), counted by a sort of integers
        # (below 2**63 while there are fewer than some hundred million nodes)
        nodes, types = len(self.keys), len(self.type_names)
        edge = (source[chosen] * nodes + target[chosen]) * types + self.entity_types[chosen]
        edge = edge * len(KINDS) + self.kinds[chosen]
        found, counts = np.unique(edge, return_counts=True)
        found, kind = np.divmod(found, len(KINDS))
        found, entity_type = np.divmod(found, types)
        source, target = np.divmod(found, nodes)
        return pd.DataFrame(
            {
                "kind": KINDS[kind],
                "source": source,
                "target": target,
                "entityType": self.type_names[entity_type],
                "count": counts,
            }
        )

    # -- earlier steps -------------------------------------------------------------------

    def held_entities(self) -> int:
        """How many entities an aggregate holds."""
        return int(((self.holder >= 0) & ~pd.isna(self.types)).sum())

    def read_memberships(self, driver: Driver, log: str) -> None:
        """Record which aggregate of earlier steps holds each node they collapsed."""
        for row in read_autocommit(driver, cypher("aggr_read_memberships"), {"log": log}):
            members = [str(m) for m in row["members"]]
            if row["type"] is None:
                codes = self.event_codes(members)
            else:
                codes = self.entity_codes(str(row["type"]), members)
            aggregate, step = [row["id"]] * len(codes), int(row["step"])
            self.hold(codes, aggregate, [row["aggregate"]] * len(codes), step)
