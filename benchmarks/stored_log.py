"""How long an analysis of a stored log takes against the same analysis of its CSV file.

    python benchmarks/stored_log.py [--sizes 10000 100000] [--repeat 3]

Starts a private Neo4j (see ``ekg_build.py``) and a private robotale home, writes the thesis'
five runs repeated as further runs (see ``dashboard.py``) as a CSV of each size, stores it as
``robotale ingest`` does (the graph, then its columnar copy) and times, in this one process,
the commands as a user runs them (best of ``--repeat`` runs, after one untimed run that
imports what the command needs):

- ``perspectives FILE.csv --json`` against ``perspectives --log NAME --json``;
- ``discover dfg FILE.csv`` against ``discover dfg --log NAME`` (the DFG from the event table);
- ``discover ekg --log NAME``, the class graph aggregated in Neo4j, which reads no event table
  (its time beside the CSV's DFG, for reference): its first call, which aggregates a key the
  ingest did not and stores it, and the calls after it.

The CSV, warm and cold runs of an analysis are interleaved (CSV, warm, cold, CSV, warm, cold
...), the best of ``--repeat`` each in wall time and in this process's CPU time (Neo4j's own
CPU is not in it); every stored run's output is checked equal to the CSV's (``differences``),
and the load average is printed before, on each line and after.

A stored log is timed *warm* (its columnar copy is there: every analysis after the ingest)
and *cold* (the copy removed before each run: a log built on another machine, or by an older
robotale: the events are read from the graph in columns and the copy is kept again). Each
figure is printed as a ratio against the CSV's time of the same analysis and size. Target:
warm within 1.2x of the CSV at 100,000 events.
"""

from __future__ import annotations

import argparse
import contextlib
import io
import json
import os
import shutil
import sys
import time
from collections.abc import Callable
from pathlib import Path

BENCHMARKS = Path(__file__).resolve().parent
sys.path.insert(0, str(BENCHMARKS))

from dashboard import private_home, thesis_runs  # noqa: E402
from ekg_build import private_neo4j  # noqa: E402

TARGET = 1.2


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--sizes", type=int, nargs="+", default=[10_000, 100_000])
    parser.add_argument("--repeat", type=int, default=3, help="runs per figure (the best)")
    parser.add_argument("--heap", default="2g", help="heap of the private Neo4j (2g)")
    args = parser.parse_args()
    print(f"load average before: {os.getloadavg()[0]:.1f} on {os.cpu_count()} cores")
    with private_home() as home, private_neo4j(args.heap) as driver:
        folder = home / "logs"
        folder.mkdir()
        for size in args.sizes:
            csv, name = store(driver, folder, size)
            measure(driver, folder, csv, name, size, args.repeat)
    print(f"load average after: {os.getloadavg()[0]:.1f}")
    return 0


def store(driver, folder: Path, size: int) -> tuple[Path, str]:
    """The log of ``size`` events as a CSV file and stored as ``robotale ingest`` stores it."""
    from robotale.ekg.build import build_ekg
    from robotale.eventlog.readers import read_log
    from robotale.eventlog.writers import write_csv

    csv = folder / f"runs_{size}.csv"
    write_csv(thesis_runs(size), csv)
    log, name = read_log(csv), f"bench_stored_{size}"
    build_ekg(driver, log, name, entities=["robot", "msg_id"], replace=True, progress=False)
    return csv, name


def measure(driver, folder: Path, csv: Path, name: str, size: int, repeat: int) -> None:
    from robotale.cli import main as robotale
    from robotale.ekg.columnar import delete_copies

    out = str(folder / "out.json")

    def run(*argv: str) -> Callable[[], object]:
        return lambda: robotale(list(argv))

    def cold(*argv: str) -> Callable[[], object]:
        return lambda: (delete_copies(name), robotale(list(argv)))[1]

    analyses = {
        "perspectives": (["perspectives", str(csv), "--json", out],
                         ["perspectives", "--log", name, "--json", out]),
        "discover dfg": (["discover", "dfg", str(csv), "--out", out],
                         ["discover", "dfg", "--log", name, "--out", out]),
    }  # fmt: skip
    print(f"{size:,} events:")
    for what, (from_file, from_store) in analyses.items():
        # once untimed: the first call imports what the analysis needs; its output is the one
        # every stored run must give
        timed(run(*from_file))
        expected = folder / "expected.json"
        shutil.copyfile(out, expected)
        sides = {"CSV": run(*from_file), "warm": run(*from_store), "cold": cold(*from_store)}
        walls: dict[str, list[float]] = {side: [] for side in sides}
        cpus: dict[str, list[float]] = {side: [] for side in sides}
        for _ in range(repeat):  # in turns: CSV, warm, cold, CSV, warm, cold ...
            for side, work in sides.items():
                wall, cpu = timed(work)
                walls[side].append(wall)
                cpus[side].append(cpu)
                differ = differences(expected, Path(out))
                if differ:
                    raise SystemExit(f"{what}, {side}: not the CSV's output: {'; '.join(differ)}")
        baseline, warm, colder = (min(walls[side]) for side in sides)
        cpu_of = {side: min(cpus[side]) for side in sides}
        verdict = f"target {TARGET}x: {'met' if warm <= TARGET * baseline else 'MISSED'}"
        print(f"  {what:<13} CSV {baseline:6.2f} s (CPU {cpu_of['CSV']:.2f} s) | stored, warm "
              f"{warm:6.2f} s (CPU {cpu_of['warm']:.2f} s; {warm / baseline:.2f}x; {verdict}) | "
              f"stored, cold {colder:6.2f} s (CPU {cpu_of['cold']:.2f} s; "
              f"{colder / baseline:.2f}x); outputs equal; best of {repeat}, in turns; load "
              f"{os.getloadavg()[0]:.1f}")  # fmt: skip
        if what == "discover dfg":
            command = run("discover", "ekg", "--log", name, "--out", out)
            # The first call aggregates the key (activity,robot) the ingest did not, in
            # Neo4j, and stores its classes; later calls read them.
            first = timed(command)[0]
            ekg = min(timed(command)[0] for _ in range(repeat))
            print(f"  {'discover ekg':<13} stored, its key's classes stored {ekg:6.2f} s "
                  f"({ekg / baseline:.2f}x the CSV's discover dfg) | first call, aggregating "
                  f"the key in Neo4j {first:6.2f} s")  # fmt: skip


def differences(expected: Path, found: Path) -> list[str]:
    """Where two JSON outputs of an analysis differ, by top-level key (empty: the same)."""
    first, second = json.loads(expected.read_text()), json.loads(found.read_text())
    if not (isinstance(first, dict) and isinstance(second, dict)):
        return [] if first == second else ["the whole output"]
    keys = list(first) + [key for key in second if key not in first]
    return [f"{key} differs" for key in keys if first.get(key) != second.get(key)]


def timed(work: Callable[[], object]) -> tuple[float, float]:
    """Wall and CPU seconds of one run of ``work`` (its printed output discarded)."""
    started, cpu = time.perf_counter(), time.process_time()
    with contextlib.redirect_stdout(io.StringIO()), contextlib.redirect_stderr(io.StringIO()):
        code = work()
    if code not in (0, None):
        raise SystemExit(f"the command failed with status {code}")
    return time.perf_counter() - started, time.process_time() - cpu


if __name__ == "__main__":
    sys.exit(main())
