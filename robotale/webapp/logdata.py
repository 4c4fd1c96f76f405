"""Stored logs as the pages need them, kept in memory between requests.

Discovery and the perspectives work on the canonical DataFrame, and the Discover page first
shows the aggregated class graph; reading either from Neo4j on every click would be slow, so
the last few stay cached (each app in its own :class:`LogData`). A cached result is used only
while the log's Log node still has the same creation time, so a log rebuilt elsewhere (the
command line, another dashboard) is read again. Concurrent requests for the same log wait for
one read instead of reading it twice.
"""

from __future__ import annotations

import threading
from collections import OrderedDict
from collections.abc import Callable, Hashable, Sequence
from typing import Any

import pandas as pd
from neo4j import Driver

from robotale.discovery.ekg import discover_ekg, read_stored_log
from robotale.ekg.aggregate import aggregation_key
from robotale.ekg.keys import DISCOVERY_KEY, built_keys
from robotale.ekg.logs import log_info as stored_log_info
from robotale.errors import InputError

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
        self.items: OrderedDict[Hashable, Any] = OrderedDict()
        self.lock = threading.Lock()
        self.loading: dict[Hashable, threading.Lock] = {}

    def get(self, key: Hashable, load: Callable[[], Any]) -> Any:
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


class LogData:
    """One app's cache of stored logs: their DataFrames and their class graphs."""

    def __init__(self, keep: int = KEEP) -> None:
        self.frames = Cache(keep)
        self.graphs = Cache(4 * keep)

    def frame(self, driver: Driver, name: str) -> pd.DataFrame:
        """The stored log ``name`` as a canonical event log."""
        version = str(log_info(driver, name).get("created"))
        return self.frames.get((name, version), lambda: read_stored_log(name, driver=driver))

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
        version = str(info.get("created"))
        return self.graphs.get(
            (name, version, tuple(key), shown),
            lambda: discover_ekg(name, list(key), entity_types, driver=driver).to_dict(),
        )

    def forget(self, name: str) -> None:
        """Drop what is cached of ``name`` (it was deleted or rebuilt)."""
        self.frames.forget(name)
        self.graphs.forget(name)


def first_key(entity_types: Sequence[str]) -> tuple[str, ...]:
    """The key of the class graph the Discover page shows first for a log: the last of those
    built with it."""
    return tuple(aggregation_key(built_keys(entity_types)[-1]))
