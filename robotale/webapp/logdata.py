"""Stored logs as event-log DataFrames, kept in memory between requests.

Discovery and the perspectives work on the canonical DataFrame; reading it back from Neo4j for
every click would be slow, so the last few logs read stay cached. A cached log is used only
while its Log node still has the same creation time, so a log rebuilt elsewhere (the command
line, another dashboard) is read again.
"""

from __future__ import annotations

import threading
from collections import OrderedDict

import pandas as pd

from robotale.errors import InputError
from robotale.webapp.neo4j_access import driver

#: how many logs stay in memory
KEEP = 4
_cache: OrderedDict[str, tuple[str, pd.DataFrame]] = OrderedDict()
_lock = threading.Lock()


def log_info(name: str) -> dict:
    """The Log node's description of ``name`` (an :class:`InputError` if there is none)."""
    from robotale.ekg.logs import list_logs

    for log in list_logs(driver()):
        if log["name"] == name:
            return log
    raise InputError(f"There is no log named {name!r} in Neo4j: upload it on the Logs page.")


def log_frame(name: str) -> pd.DataFrame:
    """The stored log ``name`` as a canonical event log."""
    from robotale.discovery.ekg import read_stored_log

    if not name:
        raise InputError("Choose a log first (upload one on the Logs page).")
    version = str(log_info(name).get("created"))
    with _lock:
        cached = _cache.get(name)
        if cached and cached[0] == version:
            _cache.move_to_end(name)
            return cached[1]
    log = read_stored_log(name, driver=driver())
    with _lock:
        _cache[name] = (version, log)
        _cache.move_to_end(name)
        while len(_cache) > KEEP:
            _cache.popitem(last=False)
    return log


def forget(name: str) -> None:
    with _lock:
        _cache.pop(name, None)
