"""Pools whose robots start their work on a signal: one process instance per message.

A FAME robot that waits for orders (a tractor for ``weed_position``, a worker for ``job``)
runs a process with a signal start event: every message starts an instance. Its trace in a
run is those instances one after the other, which the inductive miner reads as one long loop
that starts with a catch. Run that way, the robot is busy from the start of the run to its
end, so a world whose robots ignore orders while busy (``busy_ignores``) never hears one.

Where every trace of a pool begins with receiving one signal, the pool's traces are cut at
each receipt of it and mined again: the process starts on that signal, and each instance does
what the robot did for one message. Its event sub-processes are mined from the cut traces as
well, so they interrupt one instance as FAME's do.
"""

from __future__ import annotations

from dataclasses import replace

import pandas as pd

from robotale.discovery.collaboration import (
    Collaboration,
    Pool,
    handled_parts,
    mine,
    typed_instances,
)
from robotale.discovery.filters import LogFilter, filter_log
from robotale.eventlog.prepare import robot_type
from robotale.eventlog.schema import RECEIVE, ROBOT, ROBOT_TYPE


def started_on_signals(
    collaboration: Collaboration,
    log: pd.DataFrame,
    selection: LogFilter | None = None,
    *,
    noise: float = 0.0,
) -> Collaboration:
    """``collaboration`` (discovered from ``log`` and ``selection``) with each pool whose
    every trace begins with one received signal started on that signal."""
    instances = selected_instances(log, selection)
    records_aborts = bool(instances["_aborted"].any())
    pools = []
    for pool in collaboration.pools:
        mine_ = instances[instances[ROBOT_TYPE] == pool.name]
        pools.append(_started(pool, mine_, records_aborts, noise))
    return replace(collaboration, pools=pools)


def selected_instances(log: pd.DataFrame, selection: LogFilter | None) -> pd.DataFrame:
    """The activity instances of the selected events, typed as discovery types them."""
    if ROBOT in log.columns and ROBOT_TYPE not in log.columns:
        log = log.assign(
            **{ROBOT_TYPE: log[ROBOT].astype("string").map(robot_type, na_action="ignore")}
        )
    return typed_instances(filter_log(log, selection))


def _started(pool: Pool, instances: pd.DataFrame, records_aborts: bool, noise: float) -> Pool:
    parts = handled_parts(instances, records_aborts=records_aborts)
    first = _common_first(parts.main, pool)
    if first is None:
        return pool
    cut = [piece for trace in parts.main for piece in _cut(trace, first)]
    roles = {label: activity.role for label, activity in pool.stats.items()}
    block = mine([piece[1:] for piece in cut], noise, roles)
    return replace(pool, block=block, traces=len(cut), starts_on=first)


def _common_first(traces: list[list[str]], pool: Pool) -> str | None:
    """The received signal every trace begins with, if any."""
    firsts = {trace[0] if trace else None for trace in traces}
    if len(firsts) != 1:
        return None
    label = next(iter(firsts))
    stats = pool.stats.get(label) if label else None
    return label if stats is not None and stats.role == RECEIVE else None


def _cut(trace: list[str], first: str) -> list[list[str]]:
    pieces: list[list[str]] = []
    for label in trace:
        if label == first or not pieces:
            pieces.append([])
        pieces[-1].append(label)
    return pieces
