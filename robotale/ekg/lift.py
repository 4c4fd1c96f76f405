"""The edges an aggregation step lifts, computed in memory from one reading of the log.

The CORR, DF and COMM edges the build wrote are read once per run (element ids, as columns,
a range of events per query) and kept as integer codes; so is which aggregate holds each
node already collapsed. A step then needs no reading at all: the edges that touch its
members are found with numpy, their other ends mapped to what stands for them at this level
(the aggregate holding the node, else the node), counted per pair, kind and entity type with
pandas, and written in batches
(``cypher/aggr_create_lifted.cypher``). The rules are those of a step lifted in Cypher: an
edge from a member becomes an edge from its aggregate; an edge into a member from a node no
aggregate of the same step holds becomes an edge into its aggregate (so an edge between two
aggregates of one step is written once).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
import pandas as pd
from neo4j import Driver

from robotale.ekg.connection import database
from robotale.queries import cypher

#: a node no aggregate holds
FREE = -1
#: events whose edges are read in one query
EDGE_PAGE = 100_000


@dataclass
class LogEdges:
    """The log's liftable edges and who holds each node, by integer codes of element ids."""

    ids: pd.Index  # element id of each node code, then of each aggregate code appended
    kinds: np.ndarray  # 'CORR', 'DF', 'COMM' per edge
    sources: np.ndarray  # node codes
    targets: np.ndarray
    entity_types: np.ndarray  # a DF edge's entity type, '' for the others
    holder: np.ndarray  # per node code: the code of the aggregate holding it, or FREE

    @classmethod
    def read(cls, driver: Driver, log: str, stacked: bool = True) -> LogEdges:
        """``stacked``: whether earlier steps collapsed nodes of the log (if not, no node
        has an aggregate and none is looked for)."""
        row = _read_edges(driver, log)
        held: dict[str, list[str]] = {k: [] for k in ("ids", "aggregates", "nodes", "held")}
        if stacked:
            members, _, _ = driver.execute_query(
                cypher("aggr_read_memberships"), log=log, database_=database()
            )
            held = members[0].data()
        element_ids = dict(zip(held["ids"], held["aggregates"], strict=True))
        holders = [element_ids[aggregate] for aggregate in held["held"]]
        ends = np.asarray(row["sources"] + row["targets"] + held["nodes"], dtype=object)
        codes, ids = pd.factorize(ends)
        count = len(row["sources"])
        edges = cls(
            ids=pd.Index(ids, dtype=object),
            kinds=np.asarray(row["kinds"], dtype=object),
            sources=codes[:count],
            targets=codes[count : 2 * count],
            entity_types=np.asarray(row["entityTypes"], dtype=object),
            holder=np.full(len(ids), FREE, dtype=np.int64),
        )
        if held["nodes"]:
            edges.hold(codes[2 * count :], holders)
        return edges

    def hold(self, nodes: np.ndarray, aggregates: Sequence[str]) -> np.ndarray:
        """Record that each of ``nodes`` (codes) is held by the aggregate of the same
        position (element ids); returns the aggregates' codes."""
        names, positions = np.unique(np.asarray(aggregates, dtype=object), return_inverse=True)
        first = len(self.ids)
        self.ids = self.ids.append(pd.Index(names, dtype=object))
        self.holder = np.concatenate([self.holder, np.full(len(names), FREE, dtype=np.int64)])
        codes = first + positions
        self.holder[nodes] = codes
        return codes

    def codes(self, element_ids: Sequence[str]) -> np.ndarray:
        """The codes of nodes by element id (nodes with no liftable edge get new codes)."""
        found: np.ndarray = self.ids.get_indexer(pd.Index(element_ids, dtype=object))
        new = found < 0
        if new.any():
            first = len(self.ids)
            self.ids = self.ids.append(pd.Index(np.asarray(element_ids, dtype=object)[new]))
            self.holder = np.concatenate(
                [self.holder, np.full(int(new.sum()), FREE, dtype=np.int64)]
            )
            found[new] = np.arange(first, first + int(new.sum()))
        return found

    def lift(self, members: Sequence[str], aggregates: Sequence[str]) -> pd.DataFrame:
        """Collapse ``members`` into ``aggregates`` (element ids, one per member) and return
        the lifted edges of that step: ``kind``, ``source``, ``target`` (element ids),
        ``entityType`` (None but for DF) and ``count``."""
        step = np.zeros(0, dtype=np.int64)
        if len(members):
            step = self.hold(self.codes(members), aggregates)
        in_step = np.zeros(len(self.ids), dtype=bool)
        in_step[np.unique(step)] = True
        standing = np.where(self.holder >= 0, self.holder, np.arange(len(self.ids)))
        source, target = standing[self.sources], standing[self.targets]
        # out of a member; or into one from a node that no aggregate of this step holds
        chosen = in_step[source] | (in_step[target] & ~in_step[source])
        frame = pd.DataFrame(
            {
                "kind": self.kinds[chosen],
                "source": source[chosen],
                "target": target[chosen],
                "entityType": self.entity_types[chosen],
            }
        )
        lifted = frame.groupby(["kind", "source", "target", "entityType"], sort=False).size()
        lifted = lifted.rename("count").reset_index()
        lifted["source"] = self.ids[lifted["source"].to_numpy()].to_numpy()
        lifted["target"] = self.ids[lifted["target"].to_numpy()].to_numpy()
        lifted["entityType"] = lifted["entityType"].where(lifted["entityType"] != "", None)
        return lifted


def _read_edges(driver: Driver, log: str) -> dict[str, list[str]]:
    """The log's liftable edges as columns, read :data:`EDGE_PAGE` events at a time."""
    records, _, _ = driver.execute_query(
        cypher("aggr_event_positions"), log=log, database_=database()
    )
    columns: dict[str, list[str]] = {"kinds": [], "sources": [], "targets": [], "entityTypes": []}
    for first in range(0, int(records[0]["end"]), EDGE_PAGE):
        page, _, _ = driver.execute_query(
            cypher("aggr_read_edges"),
            log=log,
            first=first,
            last=first + EDGE_PAGE,
            database_=database(),
        )
        for name, values in columns.items():
            values.extend(page[0][name])
    return columns
