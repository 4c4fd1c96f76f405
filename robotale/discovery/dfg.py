"""Directly-follows graphs with pm4py (thesis 7.1.2, DFG-discovery).

The DFG relates activity instances (:mod:`robotale.discovery.instances`) that follow each other
directly within a case, ordered by their start (instances that start at the same moment in the
order of their start events in the log). Like the thesis' tool it adds an artificial start node
joined to every first activity of a case and an end node joined from every last one. Edge
durations are the time from the first activity's completion to the next one's start (zero when
they overlap, as in pm4py's performance DFG of interval logs); node durations are the
instances' own.
"""

from __future__ import annotations

import pandas as pd

from robotale.discovery.filters import LogFilter, filter_log
from robotale.discovery.graph import END_NODE, START_NODE, Edge, Node, ProcessGraph, duration_stats
from robotale.discovery.instances import (
    DURATION,
    FINISHED,
    START_TIMESTAMP,
    activity_instances,
    interrupted,
)
from robotale.errors import InputError
from robotale.eventlog.schema import ACTIVITY, CASE, REQUIRED, ROBOT, TIMESTAMP


def discover_dfg(log: pd.DataFrame, selection: LogFilter | None = None) -> ProcessGraph:
    """The directly-follows graph of the events ``selection`` keeps (all events by default).

    Nodes carry the number of finished instances, the robots performing them, their mean and
    median duration, how many instances never finished and how many were interrupted (ended
    aborted or cancelled: in the graph like any other end); edges the number of times one
    activity directly followed the other and the mean and median time between them.
    """
    import pm4py  # 2 s to import, and a banner: only discovery itself loads it

    _check_columns(log)
    events = filter_log(log, selection)
    instances = activity_instances(events)
    finished = instances[instances[FINISHED]]
    if finished.empty:
        raise InputError("the selected events contain no completed activity.")
    # pm4py orders a case's events by timestamp, stably: given the start times it keeps the
    # instances' own order, in which simultaneous starts follow the log
    by_start = finished[[CASE, ACTIVITY]].assign(**{TIMESTAMP: finished[START_TIMESTAMP]})
    frequency, starts, ends = pm4py.discover_dfg(by_start)
    waits = _waits(finished)

    graph = ProcessGraph(kind="dfg", info=_info(events, selection))
    graph.nodes = _activity_nodes(instances)
    graph.nodes += [
        Node(id=START_NODE, label="start", kind="start", count=sum(starts.values())),
        Node(id=END_NODE, label="end", kind="end", count=sum(ends.values())),
    ]
    graph.edges = [
        Edge(
            source=a,
            target=b,
            count=int(count),
            label=str(int(count)),
            durations=duration_stats(waits.get((a, b), [])),
        )
        for (a, b), count in sorted(frequency.items())
    ]
    graph.edges += [_start_end_edge(START_NODE, a, n) for a, n in sorted(starts.items())]
    graph.edges += [_start_end_edge(a, END_NODE, n) for a, n in sorted(ends.items())]
    return graph


def _check_columns(log: pd.DataFrame) -> None:
    missing = [column for column in REQUIRED if column not in log.columns]
    if missing:
        raise InputError(f"the event log has no {', '.join(missing)} column.")


def _activity_nodes(instances: pd.DataFrame) -> list[Node]:
    nodes = []
    for activity, group in instances.groupby(ACTIVITY, sort=True):
        done = group[group[FINISHED]]
        robots = sorted(group[ROBOT].dropna().astype(str).unique()) if ROBOT in group else []
        nodes.append(
            Node(
                id=str(activity),
                label=str(activity),
                count=len(done),
                robot=robots[0] if len(robots) == 1 else None,
                robots=robots,
                durations=duration_stats(done[DURATION]),
                properties={
                    "unfinished": int((~group[FINISHED]).sum()),
                    "interrupted": int(interrupted(done).sum()),
                },
            )
        )
    return [node for node in nodes if node.count or node.properties["unfinished"]]


def _waits(finished: pd.DataFrame) -> dict[tuple[str, str], list[float]]:
    """Seconds from each instance's completion to the next one's start in its case (zero
    when they overlap), per pair of activities."""
    following = finished.groupby(CASE, sort=False)[[ACTIVITY, START_TIMESTAMP]].shift(-1)
    gap = (following[START_TIMESTAMP] - finished[TIMESTAMP]).dt.total_seconds()
    pairs = pd.DataFrame(
        {"a": finished[ACTIVITY], "b": following[ACTIVITY], "wait": gap.clip(lower=0)}
    ).dropna(subset=["b"])
    return {key: list(group) for key, group in pairs.groupby(["a", "b"])["wait"]}


def _start_end_edge(source: str, target: str, count: int) -> Edge:
    return Edge(source=source, target=target, count=int(count), label=str(int(count)))


def _info(events: pd.DataFrame, selection: LogFilter | None) -> dict[str, object]:
    return {
        "filter": selection.describe() if selection else {},
        "events": len(events),
        "cases": int(events[CASE].nunique()),
        "robots": sorted(events[ROBOT].dropna().astype(str).unique()) if ROBOT in events else [],
    }
