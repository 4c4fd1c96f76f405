"""How long ``discover bpmn`` takes against pm4py's ``discover_bpmn_inductive``.

    python benchmarks/discover_bpmn.py [--sizes 10000 100000] [--runs 3]

On the synthetic multi-robot logs of ``benchmarks/discovery.py`` (start and complete events,
10 robots of two types, a third of the activities exchanging messages), in the same run,
interleaved (robotale, pm4py, robotale, pm4py ...), the best of ``--runs`` in wall time and in
CPU time (on a shared machine the CPU time says what the work costs):

- robotale: ``discover_collaboration`` (activity instances, robot types, triggers, one
  inductive miner per pool, signals, statistics) and ``write_bpmn`` (the XML and its diagram);
- pm4py, from the same log: the user's lifecycle log as robotale gets it, its start events
  kept by pm4py's own ``filter_event_attribute_values`` and ``pm4py.discover_bpmn_inductive``
  on them (one process, no pools, signals or diagram). pm4py pairs nothing on this route: on
  these logs every start completes, so the starts in time order are the activity instances
  in start order, the traces pm4py would mine after pairing. The target is judged on it;
- pm4py, on instances paired beforehand: ``pm4py.discover_bpmn_inductive`` on robotale's
  activity instances, the pairing done before the timing (stricter than the user's case:
  robotale pairs inside its timing, pm4py does not).

All outputs are checked to hold the same activities. The target is a ratio of at most 2 to
pm4py from the same log; the ratio to the pre-paired route is printed beside it.

At 10,000 events a run takes some 50 ms, a few scheduler ticks on a loaded machine, so a
small log gets more rounds (``--runs`` times 100,000 / events, at most 50), each round runs
the three in a rotated order (no one always first after the collector), garbage is
collected before each timing, and besides the best times the median of each round's own
ratio of CPU times is printed: the two measured side by side under the same load.
"""

from __future__ import annotations

import argparse
import gc
import math
import os
import statistics
import time
import warnings

import numpy as np
from discovery import synthetic_log

from robotale.discovery.bpmn_writer import write_bpmn
from robotale.discovery.collaboration import discover_collaboration
from robotale.discovery.instances import START_TIMESTAMP, activity_instances
from robotale.eventlog import schema


def typed(log):
    """Two robot types: robots 0-4 scouts, 5-9 workers."""
    number = log[schema.ROBOT].str.removeprefix("robot_").astype(int)
    return log.assign(**{schema.ROBOT_TYPE: np.where(number < 5, "Scout", "Worker")})


def robotale_run(log) -> set[str]:
    collaboration = discover_collaboration(log)
    write_bpmn(collaboration)
    return {label for pool in collaboration.pools for label in pool.stats}


def pm4py_run(intervals) -> set[str]:
    import pm4py

    model = pm4py.discover_bpmn_inductive(intervals)
    return {node.get_name() for node in model.get_nodes() if type(node).__name__ == "Task"}


def pm4py_from_log(log) -> set[str]:
    """pm4py from the user's lifecycle log: its start events, kept by pm4py's filter."""
    import pm4py

    starts = pm4py.filter_event_attribute_values(
        log, schema.LIFECYCLE, {schema.START}, level="event", retain=True
    )
    return pm4py_run(starts)


def same_activities(outputs: dict[str, set[str]]) -> bool:
    """Whether every side's model holds the same activities."""
    return len({frozenset(found) for found in outputs.values()}) == 1


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--sizes", type=int, nargs="+", default=[10_000, 100_000])
    parser.add_argument("--runs", type=int, default=3)
    args = parser.parse_args()
    warnings.simplefilter("ignore")
    print(f"load average: {' '.join(f'{v:.2f}' for v in os.getloadavg())}")
    for size in args.sizes:
        log = typed(synthetic_log(size))
        instances = activity_instances(log)
        intervals = instances[[schema.CASE, schema.ACTIVITY]].assign(
            **{schema.TIMESTAMP: instances[START_TIMESTAMP]}
        )
        runs = {
            "robotale": (robotale_run, log),
            "pm4py": (pm4py_from_log, log),
            "pm4py paired": (pm4py_run, intervals),
        }
        rounds = max(args.runs, min(50, math.ceil(args.runs * 100_000 / size)))
        wall = {name: [] for name in runs}
        cpu = {name: [] for name in runs}
        outputs = {name: run(data) for name, (run, data) in runs.items()}  # warm: imports
        names = list(runs)
        for number in range(rounds):
            # rotated: each one runs first, second and third as often
            for name in names[number % 3 :] + names[: number % 3]:
                run, data = runs[name]
                gc.collect()
                began, began_cpu = time.perf_counter(), time.process_time()
                outputs[name] = run(data)
                cpu[name].append(time.process_time() - began_cpu)
                wall[name].append(time.perf_counter() - began)
        same = same_activities(outputs)
        best = {name: min(times) for name, times in wall.items()}
        best_cpu = {name: min(times) for name, times in cpu.items()}
        paired = statistics.median(
            r / p for r, p in zip(cpu["robotale"], cpu["pm4py"], strict=True)
        )
        print(
            f"{size:>9,} events, {rounds} rounds: robotale {best['robotale']:.3f} s, pm4py from "
            f"the log {best['pm4py']:.3f} s, ratio {best['robotale'] / best['pm4py']:.2f}; CPU "
            f"robotale {best_cpu['robotale']:.3f} s, pm4py {best_cpu['pm4py']:.3f} s, ratio "
            f"{best_cpu['robotale'] / best_cpu['pm4py']:.2f}, median of the rounds' CPU ratios "
            f"{paired:.2f}; pm4py on paired instances {best['pm4py paired']:.3f} s (CPU "
            f"{best_cpu['pm4py paired']:.3f} s), ratio "
            f"{best['robotale'] / best['pm4py paired']:.2f} (CPU "
            f"{best_cpu['robotale'] / best_cpu['pm4py paired']:.2f}); same activities: {same}"
        )
    print(f"load average: {' '.join(f'{v:.2f}' for v in os.getloadavg())}")


if __name__ == "__main__":
    main()
