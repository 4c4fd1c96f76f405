"""Write the tables of :mod:`robotale.ekg.tables` into Neo4j in batches.

Each batch is one ``UNWIND`` query from ``cypher/`` run in a managed transaction (retried on
transient errors), or, for an append, all of them in the one transaction the caller gives.
Values travel as columns (one list per property) rather than one map per row: that is much
less to encode. Nodes are created first and their element ids returned, so each edge finds
its two ends directly instead of through an index (``elementId``, which every Neo4j release
keeps, rather than the deprecated ``id``).
"""

from __future__ import annotations

import datetime as dt
import itertools
import math
import os
from collections import deque
from collections.abc import Callable, Mapping, Sequence
from concurrent.futures import Future, ThreadPoolExecutor, wait
from typing import Any

import numpy as np
import pandas as pd
from neo4j import Driver, ManagedTransaction
from tqdm import tqdm

from robotale.ekg.connection import database
from robotale.errors import InputError
from robotale.queries import cypher

#: rows per transaction: 2,000 events cost the server less CPU than 5,000 or 10,000, most of
#: it in its garbage collector (a smaller transaction's state dies young; docs/ekg.md)
BATCH = 2_000
#: transactions in flight when ``ROBOTALE_BUILD_WORKERS`` does not say: one per core, at least
#: two (Neo4j runs each transaction on one core) and at most four (more only wait on each
#: other's commits and hold more transaction state in the server's heap)
WORKERS = min(4, max(2, os.cpu_count() or 2))
WORKERS_ENV = "ROBOTALE_BUILD_WORKERS"


def build_workers() -> int:
    """How many batches a build keeps in flight: ``ROBOTALE_BUILD_WORKERS`` (1 writes one
    batch after the other), else :data:`WORKERS`."""
    given = os.environ.get(WORKERS_ENV, "").strip()
    if not given:
        return WORKERS
    if not given.isdigit() or int(given) < 1:
        raise InputError(
            f"{WORKERS_ENV}={given!r} is not a number of transactions: give 1 or more."
        )
    return int(given)


class Loader:
    """Runs the batched writes of one build and shows their progress."""

    def __init__(
        self,
        driver: Driver | None,
        log: str,
        progress: tqdm | None = None,
        between_batches: Callable[[], None] = lambda: None,
        tx: ManagedTransaction | None = None,
        workers: int | None = None,
        batch: int | None = None,
    ) -> None:
        self.driver = driver
        self.log = log
        self.progress = progress
        self.between_batches = between_batches  # e.g. DeferredInterrupt.check
        # With a transaction every batch goes into it, one after the other: an append is
        # kept or undone as a whole.
        self.tx = tx
        # batches that all reach the same few nodes only wait on each other's locks: one
        self.workers = build_workers() if workers is None else workers
        # rows per transaction; the module's BATCH read now, not when this was defined (the
        # edges' ``batches`` and :func:`within_batches` are cut by it: they must agree)
        self.batch = BATCH if batch is None else batch

    def run(
        self,
        query: str,
        columns: Mapping[str, Sequence[Any]],
        maps: Mapping[str, Mapping[str, Sequence[Any]]] | None = None,
        batches: Mapping[str, Sequence[Any]] | None = None,
        **constants: Any,
    ) -> list[str]:
        """Run ``cypher/<query>.cypher`` once per batch of ``columns``.

        ``maps`` are parameters that are maps of columns ({key: [values]}); they are cut into
        the same batches. ``batches`` are parameters given whole for each batch: item k of
        each goes with batch k. Returns the element ids of the queries' ``nodes`` results in
        row order.
        """
        text = cypher(query)
        size = len(next(iter(columns.values())))

        def write(start: int) -> list[str]:
            self.between_batches()
            params: dict[str, Any] = {
                n: _slice(values, start, self.batch) for n, values in columns.items()
            }
            for name, columns_of_map in (maps or {}).items():
                params[name] = {k: _slice(v, start, self.batch) for k, v in columns_of_map.items()}
            for name, values in (batches or {}).items():
                params[name] = values[start // self.batch]
            records = self._execute(text, params | constants | {"log": self.log})
            if self.progress is not None:
                self.progress.update(min(self.batch, size - start))
            created = records[0].get("nodes") if records else None
            return [node for _, node in sorted(created or [])]

        if self.tx is not None:
            return [node for start in range(0, size, self.batch) for node in write(start)]
        return _in_flight(write, range(0, size, self.batch), self.workers)

    def together(self, *parts: Callable[[], None]) -> None:
        """Run ``parts``, writes of which no two touch the same node, at the same time, each in
        transactions of its own, so that Neo4j works on them with as many cores; one after
        the other in the caller's transaction (an append) or with one worker. The first
        failure is raised once every part has ended."""
        if self.tx is not None or self.workers < 2 or len(parts) < 2:
            for part in parts:
                part()
            return
        with ThreadPoolExecutor(max_workers=len(parts)) as pool:
            running = [pool.submit(part) for part in parts]
            wait(running)
        for done in running:
            done.result()

    def _execute(self, text: str, parameters: dict[str, Any]) -> list[Any]:
        if self.tx is not None:
            return list(self.tx.run(text, parameters))
        assert self.driver is not None, "a Loader without a transaction needs a driver"
        records, _, _ = self.driver.execute_query(text, parameters, database_=database())
        return records

    def events(
        self,
        events: pd.DataFrame,
        entities: list[list[str]],
        classes: list[list[str]],
        df: pd.DataFrame,
        comm: pd.DataFrame,
        first: int = 0,
    ) -> np.ndarray:
        """Create the events with their CORR and OBSERVED edges (``entities``, ``classes``:
        element ids per event) and the rows of ``df`` and ``comm`` (event positions) that lie
        within one batch (:func:`within_batches`); ``first`` is the first event's position
        in the stored log.

        Returns the events' element ids by row.
        """
        times = events["timestamp"]
        nanos = times.dt.tz_convert("UTC").dt.as_unit("ns").astype("int64").to_numpy()
        columns = {
            "ids": events["id"].tolist(),
            "orders": list(range(first, first + len(events))),
            "seconds": (nanos // 1_000_000_000).tolist(),
            "nanos": (nanos % 1_000_000_000).tolist(),
            "entities": entities,
            "classes": classes,
        }
        others = [c for c in events.columns if c not in ("id", "timestamp")]
        properties = {name: neo4j_values(events[name]) for name in others}
        count = -(-len(events) // BATCH)
        batches = {
            "df": _per_batch(df, count, entityTypes="entityType", entityIds="entityId"),
            "comm": _per_batch(comm, count, msgIds="msgId"),
        }
        nodes = self.run(
            "ekg_create_events",
            columns,
            {"properties": properties},
            batches,
            timezone=timezone_name(times),
        )
        return np.asarray(nodes, dtype=object)


def within_batches(edges: pd.DataFrame) -> np.ndarray:
    """Which rows of ``edges`` (``source``, ``target``: event positions) join two events of
    the same batch, so that :meth:`Loader.events` writes them with their events."""
    same: np.ndarray = (edges["source"].to_numpy() // BATCH) == (
        edges["target"].to_numpy() // BATCH
    )
    return same


def _per_batch(edges: pd.DataFrame, count: int, **properties: str) -> list[dict[str, list[Any]]]:
    """For each of ``count`` batches, its edges of ``edges`` as columns: ``sources`` and
    ``targets`` by position in the batch, and each of ``properties`` (parameter: column)."""
    batch = edges["source"].to_numpy() // BATCH
    # one sort, then a slice per batch: a mask per batch would read every edge once per batch
    order = np.argsort(batch, kind="stable")
    edges = edges.iloc[order]
    bounds = np.searchsorted(batch[order], np.arange(count + 1)).tolist()
    parts = []
    for start, end in itertools.pairwise(bounds):
        part = edges.iloc[start:end]
        columns = {
            "sources": (part["source"].to_numpy() % BATCH).tolist(),
            "targets": (part["target"].to_numpy() % BATCH).tolist(),
        }
        parts.append(columns | {name: part[c].tolist() for name, c in properties.items()})
    return parts


def _in_flight(
    write: Callable[[int], list[str]], starts: range, workers: int = WORKERS
) -> list[str]:
    """``write`` for each start, ``workers`` at a time, results in order.

    Neo4j runs each transaction on one core; with two in flight it uses two. Batches that
    collide on a node are retried by the driver's managed transactions. Nothing new starts
    once one batch has failed.
    """
    nodes: list[str] = []
    with ThreadPoolExecutor(max_workers=workers) as pool:
        running: deque[Future[list[str]]] = deque()
        for start in starts:
            running.append(pool.submit(write, start))
            if len(running) == workers:
                nodes.extend(running.popleft().result())
        while running:
            nodes.extend(running.popleft().result())
    return nodes


def _slice(values: Sequence[Any], start: int, batch: int) -> Sequence[Any]:
    return values[start : start + batch]


def neo4j_values(column: pd.Series) -> list[Any]:
    """The column as Python values Neo4j can store; missing values become None."""
    if pd.api.types.is_bool_dtype(column) or pd.api.types.is_integer_dtype(column):
        return list(column.astype(object).where(column.notna(), None).tolist())
    if pd.api.types.is_float_dtype(column):
        values = column.to_numpy(float)
        if not np.isnan(values).any():  # a column without gaps: no test per value
            return list(values.tolist())
        return [None if math.isnan(v) else v for v in values.tolist()]
    if pd.api.types.is_datetime64_any_dtype(column):
        return [None if pd.isna(v) else v.to_pydatetime() for v in column]
    if pd.api.types.infer_dtype(column, skipna=True) == "string":  # the usual log's columns
        return list(column.astype(object).where(column.notna(), None).tolist())
    return [_storable(v) for v in column.astype(object).tolist()]


def _storable(value: Any) -> Any:
    if value is None or value is pd.NA or (isinstance(value, float) and math.isnan(value)):
        return None
    if isinstance(value, str | bool | int | float):
        return value
    if isinstance(value, np.generic):
        return value.item()
    if isinstance(value, list | tuple | np.ndarray):
        return [str(v) for v in value]
    if isinstance(value, dt.datetime | pd.Timestamp):
        return value
    return str(value)


def timezone_name(times: pd.Series) -> str:
    """The zone Neo4j should show the times in: an IANA name or a fixed offset like +01:00."""
    zone = times.dt.tz
    name = getattr(zone, "key", None) or getattr(zone, "zone", None)
    if name is not None and ("/" in name or name == "UTC"):
        return str(name)
    offset = times.iloc[0].utcoffset() or dt.timedelta(0)
    minutes = int(offset.total_seconds() // 60)
    sign = "-" if minutes < 0 else "+"
    return f"{sign}{abs(minutes) // 60:02d}:{abs(minutes) % 60:02d}"
