"""Stored logs as the pages need them, computed once per build of a log.

Discovery and the perspectives work on the canonical DataFrame (read from the log's columnar
copy, :mod:`robotale.ekg.columnar`), and the last few stay in memory (each app in its own
:class:`LogData`). What the pages show of a log (each perspective, the findings, the timeline,
the class graph) is computed once per build and kept as JSON in the build's folder beside the
copy, so no later visit, and no restarted dashboard, computes it again; a new build of the
log (the command line, another dashboard) gets a new folder. Concurrent requests for the same
log wait for one read or one computation instead of doing it twice.
"""

from __future__ import annotations

import contextlib
import hashlib
import io
import json
import re
import threading
from collections import Counter, OrderedDict
from collections.abc import Callable, Hashable, Sequence
from pathlib import Path
from typing import Any

import pandas as pd
import pyarrow as pa
import pyarrow.parquet as pq
from neo4j import Driver

from robotale.discovery.ekg import discover_ekg
from robotale.discovery.ekg_table import computable, table_class_graph
from robotale.discovery.graph import json_ready
from robotale.ekg.aggregate import aggregation_key
from robotale.ekg.columnar import Build, log_build, results_folder, stored_table
from robotale.ekg.keys import DISCOVERY_KEY, built_keys
from robotale.ekg.logs import log_info as stored_log_info
from robotale.enhancement.context import LogAnalysis
from robotale.errors import InputError
from robotale.files import write_file, write_files

#: how many logs (and class graphs) stay in memory
KEEP = 4
#: the class graph the Discover page shows when none is named
DEFAULT_KEY = tuple(aggregation_key(DISCOVERY_KEY))
#: what a missing log's message tells the dashboard's user
MISSING_HINT = "upload it on the Logs page"


class Cache:
    """A small LRU cache of values keyed by tuples whose first item is the log's name."""

    def __init__(self, size: int) -> None:
        self.size = size
        self.items: OrderedDict[tuple[Hashable, ...], Any] = OrderedDict()
        self.lock = threading.Lock()
        self.loading: dict[tuple[Hashable, ...], threading.Lock] = {}

    def get(self, key: tuple[Hashable, ...], load: Callable[[], Any]) -> Any:
        with self.lock:
            if key in self.items:
                self.items.move_to_end(key)
                return self.items[key]
            loading = self.loading.setdefault(key, threading.Lock())
        with loading:  # one read per key; the others wait for it
            with self.lock:
                if key in self.items:
                    return self.items[key]
            value = load()
            with self.lock:
                self.items[key] = value
                self.loading.pop(key, None)
                while len(self.items) > self.size:
                    self.items.popitem(last=False)
            return value

    def forget(self, name: str) -> None:
        with self.lock:
            for key in [k for k in self.items if k[0] == name]:
                del self.items[key]


def log_info(driver: Driver, name: str) -> dict[str, Any]:
    """The Log node's description of ``name`` (a :class:`LogNotFound` if there is none)."""
    if not name:
        raise InputError("Choose a log first (upload one on the Logs page).")
    return stored_log_info(driver, name, MISSING_HINT)


def current_build(driver: Driver, name: str) -> Build:
    """The build of the stored log ``name`` (a :class:`LogNotFound` if there is none)."""
    if not name:
        raise InputError("Choose a log first (upload one on the Logs page).")
    return log_build(driver, name, MISSING_HINT)


class LogData:
    """One app's stored logs: their DataFrames in memory, their results on disk."""

    def __init__(self, keep: int = KEEP) -> None:
        self.frames = Cache(keep)
        #: the tables the perspectives and findings share (activity instances, steps, message
        #: tables), of the last log analysed: its sections and findings computed one after
        #: the other build them once; one log only, as they outweigh the log itself
        self.analyses = Cache(1)
        self.graphs = Cache(4 * keep)
        #: the runs the Mission page replays, and the models' elements they map to
        self.missions = Cache(4 * keep)
        #: how often each kind of result of each log was computed (not read from disk), by
        #: (log, kind): what the tests count
        self.computed: Counter[tuple[str, str]] = Counter()
        self._lock = threading.Lock()
        #: one lock per log and turn; re-entrant: a computation may need another result of
        #: its log first (a Mission run, the log's slow limits)
        self._computing: dict[tuple[str, str], threading.RLock] = {}

    def frame(self, driver: Driver, name: str) -> pd.DataFrame:
        """The stored log ``name`` as a canonical event log."""
        build = current_build(driver, name)
        return self.frames.get((name, build.key), lambda: stored_table(driver, name, MISSING_HINT))

    def analysis(self, driver: Driver, name: str) -> LogAnalysis:
        """The stored log ``name`` as an analysis whose shared tables later computations of
        the same build reuse."""
        build = current_build(driver, name)
        analysis: LogAnalysis = self.analyses.get(
            (name, build.key), lambda: LogAnalysis(self.frame(driver, name))
        )
        return analysis

    def result(
        self,
        driver: Driver,
        name: str,
        what: Sequence[str],
        compute: Callable[[], Any],
        turn: str = "",
    ) -> bytes:
        """The JSON of ``compute()`` for the current build of ``name``: read from the build's
        folder when it was computed before, else computed (one computation per log and
        ``turn`` at a time, so the section a page asks for first is ready first) and kept."""
        build = current_build(driver, name)
        if not build.complete:  # being written or failed: nothing to keep it for
            return result_json(compute())
        path = results_folder(build) / _file_name(what)
        with self._lock:
            computing = self._computing.setdefault((name, turn), threading.RLock())
        data = _read(path)
        if data is not None:
            return data
        with computing:
            data = _read(path)
            if data is None:
                data = result_json(compute())
                write_file(path, data)
                self.computed[(name, what[0])] += 1
        return data

    def tables(
        self,
        driver: Driver,
        name: str,
        what: Sequence[str],
        compute: Callable[[], tuple[dict[str, Any], dict[str, pd.DataFrame]]],
    ) -> tuple[dict[str, Any], dict[str, pd.DataFrame]]:
        """Plain values and tables of the current build of ``name``, ``compute()`` once per
        build and kept in its folder (the values as JSON, each table in Parquet), so a later
        request, or a restarted dashboard, reads them instead. What is returned is always
        what was read back, so the first answer is the same as every later one; tables
        Parquet cannot hold are computed each time."""
        build = current_build(driver, name)
        if not build.complete:  # being written or failed: nothing to keep it for
            return compute()
        folder = results_folder(build)
        values_path = folder / _file_name(what)
        with self._lock:
            computing = self._computing.setdefault((name, ""), threading.RLock())
        found = _read_tables(folder, what, values_path)
        if found is not None:
            return found
        with computing:
            found = _read_tables(folder, what, values_path)
            if found is not None:
                return found
            values, tables = compute()
            try:
                files = [(folder / _table_name(what, t), _parquet(tables[t])) for t in tables]
            except (pa.ArrowException, ValueError, TypeError):  # a column of mixed kinds
                return values, tables
            # the values last: they name the tables, so a reader finds all or none
            files.append((values_path, result_json({"values": values, "tables": list(tables)})))
            write_files(files)
            self.computed[(name, what[0])] += 1
            found = _read_tables(folder, what, values_path)
        return found if found is not None else (values, tables)

    def class_graph(
        self,
        driver: Driver,
        name: str,
        key: Sequence[str] = DEFAULT_KEY,
        entity_types: Sequence[str] | None = None,
    ) -> dict[str, Any]:
        """The aggregated EKG of ``name`` by ``key`` with the flow of ``entity_types`` (all
        the log's when None), as :meth:`ProcessGraph.to_dict` gives it."""
        info = log_info(driver, name)
        if entity_types is not None and set(entity_types) == set(info.get("entityTypes") or []):
            entity_types = None  # the same graph as "all", so the same cache entry
        shown = tuple(entity_types) if entity_types is not None else None
        version = current_build(driver, name).key  # a rebuild or an append is a new build

        def compute() -> dict[str, Any]:
            what = ("class-graph", *key, "|", *(shown or ("all",)))
            data = self.result(
                driver,
                name,
                what,
                lambda: self._class_graph(driver, name, info, key, entity_types),
                # mostly Neo4j's work: in its own turn, beside the sections computed here
                turn="class-graph",
            )
            graph: dict[str, Any] = json.loads(data)
            return graph

        found: dict[str, Any] = self.graphs.get((name, version, tuple(key), shown), compute)
        return found

    def _class_graph(
        self,
        driver: Driver,
        name: str,
        info: dict[str, Any],
        key: Sequence[str],
        entity_types: Sequence[str] | None,
    ) -> dict[str, Any]:
        """The class graph computed from the log's event table (the copy the pages read
        anyway) when it holds the key and the entity types, else read from Neo4j (which
        also says what a request names wrongly)."""
        known = list(info.get("entityTypes") or [])
        types = known if entity_types is None else list(entity_types)
        properties = aggregation_key(list(key))
        frame = self.frame(driver, name)
        if set(types) <= set(known) and computable(frame, properties, types):
            # refused when no event names an entity of the chosen types: the stored graph
            # answers that, as it always did (no edges of those types)
            with contextlib.suppress(InputError):
                return table_class_graph(name, frame, properties, types).to_dict()
        return discover_ekg(name, list(key), entity_types, driver=driver).to_dict()

    def forget(self, name: str) -> None:
        """Drop what is kept in memory of ``name`` (it was deleted or rebuilt)."""
        self.frames.forget(name)
        self.analyses.forget(name)
        self.graphs.forget(name)
        self.missions.forget(name)


def _file_name(what: Sequence[str]) -> str:
    """A file name for the result ``what`` (its words, readable, and a digest of them all:
    activity and robot names may hold any character)."""
    words = re.sub(r"[^\w.-]+", "_", "-".join(what))[:60]
    digest = hashlib.sha256("\x00".join(what).encode("utf-8")).hexdigest()[:16]
    return f"{words}-{digest}.json"


def _table_name(what: Sequence[str], table: str) -> str:
    return _file_name((*what, table)).removesuffix(".json") + ".parquet"


def _parquet(table: pd.DataFrame) -> bytes:
    sink = io.BytesIO()
    pq.write_table(pa.Table.from_pandas(table), sink)
    return sink.getvalue()


def _read_tables(
    folder: Path, what: Sequence[str], values_path: Path
) -> tuple[dict[str, Any], dict[str, pd.DataFrame]] | None:
    """The values and tables :meth:`LogData.tables` kept, or None when they are not all
    there (or cannot be read: they are computed again)."""
    data = _read(values_path)
    if data is None:
        return None
    try:
        kept = json.loads(data)
        tables = {
            str(t): pq.read_table(folder / _table_name(what, str(t))).to_pandas()
            for t in kept["tables"]
        }
    except (OSError, ValueError, KeyError, TypeError, pa.ArrowException):
        return None
    return kept["values"], tables


def result_json(value: Any) -> bytes:
    """A result as the pages receive it: compact JSON, with what JSON lacks made plain."""
    return json.dumps(json_ready(value), separators=(",", ":")).encode("utf-8")


def _read(path: Path) -> bytes | None:
    """A kept result, or None when there is none (or it cannot be read: it is computed again)."""
    try:
        data = path.read_bytes()
    except OSError:
        return None
    return data if data else None


def first_key(entity_types: Sequence[str]) -> tuple[str, ...]:
    """The key of the class graph the Discover page shows first for a log: the last of those
    built with it."""
    return tuple(aggregation_key(built_keys(entity_types)[-1]))
