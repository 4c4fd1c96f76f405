"""How fast discovery and the perspectives run on large logs.

    python benchmarks/discovery.py [--sizes 100000 1000000]

For synthetic multi-robot logs (start and complete events, 10 robots, a third of the activities
exchanging messages), in the same run:

1. ``discover_dfg`` (activity instances, start/end nodes, durations) against pm4py's own route
   to the same graph: lifecycle log -> interval log -> ``pm4py.discover_dfg``; and against
   plain ``pm4py.discover_dfg`` on the raw events, which pairs nothing (the floor); the
   interval route is left out above 200,000 events;
2. the performance perspective (working and waiting time, variants per case and per robot,
   case durations) and the effect-ranked bottlenecks, sharing one ``LogAnalysis`` of the log
   (activity instances, steps and case durations built once), against pm4py's own discovery and
   performance functions on the same DataFrame: ``pm4py.discover_dfg``,
   ``pm4py.discover_performance_dfg``, ``pm4py.get_variants`` and
   ``pm4py.get_all_case_durations`` (the target: within 2x of their sum), each the best of
   ``--runs`` runs (3);
3. all perspectives at once (``all_perspectives``), as a ratio to plain ``pm4py.discover_dfg``.

Ratios above 1 mean robotale takes longer than the baseline.
"""

from __future__ import annotations

import argparse
import os
import time
import warnings

import numpy as np
import pandas as pd

from robotale.eventlog import schema

#: above this size pm4py's interval route (Python objects per event) is left out: minutes
INTERVAL_ROUTE_LIMIT = 200_000
ACTIVITIES = ["explore", "move", "cut_grass", "scan", "charge", "report"]
MESSAGES = ["weed_position", "tractor_position", "closest_tractor"]


def synthetic_log(events: int, seed: int = 3) -> pd.DataFrame:
    """Runs of 200 events; every activity instance is a start and a complete 0-20 s apart."""
    rng = np.random.default_rng(seed)
    instances = events // 2
    robots = rng.integers(0, 10, instances)
    is_message = rng.random(instances) < 1 / 3
    names = np.where(
        is_message,
        np.array(MESSAGES)[rng.integers(0, 3, instances)]
        + np.where(rng.random(instances) < 0.5, "!", "?"),
        np.array(ACTIVITIES)[rng.integers(0, len(ACTIVITIES), instances)],
    )
    starts = np.cumsum(rng.exponential(5.0, instances))
    ends = starts + rng.uniform(0, 20, instances)
    base = pd.Timestamp("2024-01-01", tz="UTC")
    one = pd.DataFrame(
        {
            schema.CASE: (np.arange(instances) // 100).astype(str),
            schema.ROBOT: np.char.add("robot_", robots.astype(str)),
            schema.ACTIVITY: names,
            schema.MSG_ID: np.where(
                is_message, np.char.add("m", (np.arange(instances) // 3).astype(str)), None
            ),
            schema.X: rng.uniform(0, 10, instances),
            schema.Y: rng.uniform(0, 10, instances),
            schema.BATTERY: 100 - (np.arange(instances) % 100) * 0.5,
        }
    )
    start = one.assign(
        **{schema.LIFECYCLE: "start", schema.TIMESTAMP: base + pd.to_timedelta(starts, "s")}
    )
    done = one.assign(
        **{schema.LIFECYCLE: "complete", schema.TIMESTAMP: base + pd.to_timedelta(ends, "s")}
    )
    log = pd.concat([start, done], ignore_index=True)
    return log.sort_values(schema.TIMESTAMP, kind="stable", ignore_index=True)


def timed(function, *args, **kwargs) -> float:
    began = time.perf_counter()
    function(*args, **kwargs)
    return time.perf_counter() - began


def pm4py_interval_dfg(log: pd.DataFrame) -> None:
    import pm4py
    from pm4py.objects.log.util import interval_lifecycle

    event_log = pm4py.convert_to_event_log(log.assign(**{"concept:instance": log[schema.MSG_ID]}))
    pm4py.discover_dfg(interval_lifecycle.to_interval(event_log))


def pm4py_performance(log: pd.DataFrame) -> None:
    """pm4py's discovery and performance functions on the same DataFrame."""
    import pm4py

    pm4py.discover_dfg(log)
    pm4py.discover_performance_dfg(log)
    pm4py.get_variants(log)
    pm4py.get_all_case_durations(log)


def robotale_performance(log: pd.DataFrame) -> None:
    """The same questions answered by robotale: performance with variants, and bottlenecks,
    sharing one analysis of the log as ``all_perspectives`` does."""
    from robotale.enhancement import LogAnalysis, find_bottlenecks, performance_perspective

    analysis = LogAnalysis(log)
    performance_perspective(analysis)
    find_bottlenecks(analysis)


def main() -> int:
    import pm4py

    from robotale.discovery import discover_dfg
    from robotale.enhancement import all_perspectives

    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--sizes", type=int, nargs="+", default=[100_000])
    parser.add_argument("--runs", type=int, default=3, help="runs of the performance work (best)")
    args = parser.parse_args()
    sizes = args.sizes
    warnings.simplefilter("ignore")
    print("load average (1, 5, 15 min): " + ", ".join(f"{n:.1f}" for n in os.getloadavg()))
    warm = synthetic_log(2_000)  # imports and first-call costs stay out of the figures
    for warm_up in (discover_dfg, pm4py.discover_dfg, all_perspectives, pm4py_performance):
        warm_up(warm)
    for size in sizes:
        log = synthetic_log(size)
        floor = timed(pm4py.discover_dfg, log)
        ours = timed(discover_dfg, log)
        theirs = timed(pm4py_interval_dfg, log) if size <= INTERVAL_ROUTE_LIMIT else None
        # the best of several runs: a busy moment of a shared machine weighs less
        pm4py_work = min(timed(pm4py_performance, log) for _ in range(args.runs))
        our_work = min(timed(robotale_performance, log) for _ in range(args.runs))
        perspectives = timed(all_perspectives, log)
        rows = [
            ("pm4py.discover_dfg on raw events (baseline)", floor, ""),
            ("robotale discover_dfg", ours, ""),
            ("pm4py dfg + performance dfg + variants + durations", pm4py_work, ""),
            (
                "robotale performance + variants + bottlenecks",
                our_work,
                f"{our_work / pm4py_work:.2f}x pm4py's performance functions",
            ),
            ("all perspectives + bottlenecks", perspectives, ""),
        ]
        if theirs is not None:
            note = f"robotale {theirs / ours:.1f}x faster"
            rows.insert(2, ("pm4py interval route to the same graph", theirs, note))
        print(f"== {len(log):,} events, {log[schema.CASE].nunique():,} cases")
        for name, seconds, note in rows:
            print(f"  {name:52} {seconds:7.2f} s {seconds / floor:6.1f}x baseline  {note}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
