"""How long ``robotale compare`` takes on two batches of 100,000 events, against reading the
findings of both batches side by side.

    python benchmarks/compare.py [--sizes 10000 100000] [--runs 3]

The batches are twelve simulated runs of the agri scenario (simulated and prepared first,
untimed) repeated as further runs until they have the given number of events, each run's
clock stretched by a factor of its own (0.8 to 1.2 in A, so the runs of a batch differ; 0.9
to 1.3 in B: a change to find). In the same process,
interleaved (compare, findings, compare, findings ...), best of ``--runs``:

- *compare*: ``robotale.enhancement.compare.compare_logs(A, B)``, every measure per run and
  its test, the variants, the bottlenecks of both batches and the sentences;
- *findings of A and B*: ``robotale.enhancement.findings.find`` of each batch, the analysis
  one would otherwise read twice and set side by side (its bottlenecks and perspectives are
  the same work the comparison does on each batch, without the tests between them).

- *the whole command*: ``robotale compare A.csv B.csv`` as the user runs it, a process of its
  own (start, imports, reading both files, the comparison, the printed text), the batches
  written to CSV beforehand; its wall time and the CPU time of the process, and how often it
  waited (voluntary context switches) or was preempted (involuntary ones): a wall time far
  above the CPU time with few waits is time queued behind other work, not waiting.

The runs' mean duration the comparison reports is checked equal to the findings' for each
batch, and the command's first sentence equal to the function's. Target: compare under 5 s
at 100,000 events per batch, the function and the whole command; the ratio to the findings
is printed beside it. On a shared machine the CPU time says what the work costs.
"""

from __future__ import annotations

import argparse
import os
import resource
import subprocess
import sys
import tempfile
import time
import warnings
from functools import partial
from pathlib import Path

import numpy as np
import pandas as pd

sys.path.insert(0, str(Path(__file__).resolve().parent))


TARGET_SECONDS = 5.0


def simulated(folder: Path) -> pd.DataFrame:
    """Twelve runs of the agri scenario, prepared."""
    from robotale.eventlog.prepare import prepare
    from robotale.sim.batch import simulate_batch
    from robotale.sim.plans import plans, resolve_world

    world = resolve_world("agri")[0]
    simulate_batch(plans(world, "agri", runs=12, seed=1), folder, workers=0)
    return prepare(folder)


def repeated(template: pd.DataFrame, events: int) -> pd.DataFrame:
    """``template``'s runs repeated, a day apart, as further runs until ``events`` events."""
    from robotale.eventlog import schema

    copies, total, copy = [], 0, 0
    while total < events:
        run = template.copy()
        run[schema.CASE] = f"{copy}_" + run[schema.CASE].astype(str)
        run[schema.TIMESTAMP] = run[schema.TIMESTAMP] + pd.Timedelta(days=copy)
        for column in (schema.MSG_ID, schema.EVENT_ID):
            run[column] = (f"{copy}_" + run[column].astype("string")).where(run[column].notna())
        copies.append(run)
        total += len(run)
        copy += 1
    return pd.concat(copies, ignore_index=True).head(events)


def batch(template: pd.DataFrame, events: int, seed: int, slower: float) -> pd.DataFrame:
    """``template`` repeated, each run's clock stretched by its own factor, ``slower`` times
    one between 0.8 and 1.2."""
    from robotale.eventlog import schema

    log = repeated(template, events)
    rng = np.random.default_rng(seed)
    runs = log[schema.CASE]
    start = log.groupby(runs)[schema.TIMESTAMP].transform("min")
    factors = slower * rng.uniform(0.8, 1.2, runs.nunique())
    factor = runs.map(dict(zip(runs.unique(), factors, strict=True)))
    offset = (log[schema.TIMESTAMP] - start) * factor.to_numpy()
    log[schema.TIMESTAMP] = start + offset
    return log.sort_values([schema.CASE, schema.TIMESTAMP], kind="stable").reset_index(drop=True)


def mean_durations(comparison, findings) -> tuple[list[float], list[float]]:
    """The runs' mean durations of batches A and B as the comparison reports them, and as the
    findings of each batch give them: the benchmark checks the two equal."""
    row = comparison.changes.query("measure == 'run duration'").iloc[0]
    return [float(row["a"]), float(row["b"])], [float(f.runs["duration"].mean()) for f in findings]


#: the least CPU seconds of each function :func:`best_of` timed in this process, by position
CPU: list[float] = []


def best_of(runs: int, *functions):
    """Each function's least wall-clock seconds and its last result, called in turns (its
    least CPU seconds of this process in :data:`CPU`)."""
    times: list[list[float]] = [[] for _ in functions]
    spent: list[list[float]] = [[] for _ in functions]
    results: list[object] = [None] * len(functions)
    for _ in range(runs):
        for index, function in enumerate(functions):
            began, began_cpu = time.perf_counter(), time.process_time()
            results[index] = function()
            times[index].append(time.perf_counter() - began)
            spent[index].append(time.process_time() - began_cpu)
    CPU[:] = [min(s) for s in spent]
    return [min(t) for t in times], results


def _both(function, first, second):
    return function(first), function(second)


class Command:
    """``robotale compare A B`` run as a process; its least CPU time kept, and how often the
    process of that turn gave up the processor to wait (voluntary context switches: reading
    a file, a lock, a socket) and how often the scheduler took it away (involuntary: other
    work on a busy machine), which tell a wall time spent waiting from one spent queued."""

    def __init__(self, first: Path, second: Path) -> None:
        self.arguments = [sys.executable, "-m", "robotale", "compare", str(first), str(second)]
        self.cpu = float("inf")
        self.switches = (0, 0)  # (voluntary, involuntary) of the turn with the least CPU

    def __call__(self) -> str:
        before = resource.getrusage(resource.RUSAGE_CHILDREN)
        done = subprocess.run(self.arguments, capture_output=True, text=True, check=True)
        after = resource.getrusage(resource.RUSAGE_CHILDREN)
        spent = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
        if spent < self.cpu:
            self.cpu = spent
            self.switches = (
                after.ru_nvcsw - before.ru_nvcsw,
                after.ru_nivcsw - before.ru_nivcsw,
            )
        return done.stdout


def main() -> int:
    from robotale.enhancement.compare import compare_logs

    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--sizes", type=int, nargs="+", default=[10_000, 100_000])
    parser.add_argument("--runs", type=int, default=3, help="turns of each (best)")
    args = parser.parse_args()
    warnings.simplefilter("ignore")
    with tempfile.TemporaryDirectory(prefix="robotale-bench-compare-") as scratch:
        template = simulated(Path(scratch) / "runs")
        small = batch(template, 2_000, 0, 1.0)
        compare_logs(small, small)  # imports and first calls stay out of the figures
        load()
        for size in args.sizes:
            measure(template, size, args.runs, Path(scratch))
        load()
    return 0


def load() -> None:
    print("load average (1, 5, 15 min): " + ", ".join(f"{n:.1f}" for n in os.getloadavg()))


def measure(template: pd.DataFrame, size: int, runs: int, scratch: Path) -> None:
    """The three timings at one size, printed."""
    from robotale.enhancement.compare import compare_logs
    from robotale.enhancement.findings import find

    first, second = batch(template, size, 1, 1.0), batch(template, size, 2, 1.1)
    files = [scratch / f"{name}_{size}.csv" for name in ("A", "B")]
    for log, file in zip((first, second), files, strict=True):
        log.to_csv(file, index=False)
    command = Command(*files)
    (ours, theirs, whole), (comparison, findings, printed) = best_of(
        runs,
        partial(compare_logs, first, second),
        partial(_both, find, first, second),
        command,
    )
    reported, means = mean_durations(comparison, findings)
    assert np.allclose(reported, means), (reported, means)
    print(f"== two batches of {size:,} events ({first['case:concept:name'].nunique()} runs "
          f"each; runs' mean durations checked equal to the findings')")  # fmt: skip
    print(f"  {'compare A B':40} {ours:7.2f} s  (CPU {CPU[0]:.2f} s; target < "
          f"{TARGET_SECONDS:g} s: {'met' if ours < TARGET_SECONDS else 'MISSED'} in wall "
          f"time, {'met' if CPU[0] < TARGET_SECONDS else 'MISSED'} in CPU time)")  # fmt: skip
    print(f"  {'robotale compare A.csv B.csv (command)':40} {whole:7.2f} s  (CPU "
          f"{command.cpu:.2f} s; target < {TARGET_SECONDS:g} s: "
          f"{'met' if whole < TARGET_SECONDS else 'MISSED'} in wall time, "
          f"{'met' if command.cpu < TARGET_SECONDS else 'MISSED'} in CPU time)")  # fmt: skip
    waited, queued = command.switches
    print(f"  {'':40} the command waited {waited} times, was preempted {queued} times")
    assert comparison.sentences[0] in printed, "the command says another first sentence"
    print(f"  {'findings of A and of B':40} {theirs:7.2f} s  (CPU {CPU[1]:.2f} s)")
    print(f"  {'compare / findings':40} {ours / theirs:7.2f} x")
    print(f"  first sentence: {comparison.sentences[0]}")


if __name__ == "__main__":
    raise SystemExit(main())
