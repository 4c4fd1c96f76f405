"""How long reading a CSV event log takes against pandas reading the same file plainly.

    python benchmarks/read_csv.py [--sizes 100000 1000000] [--runs 3]

On the synthetic multi-robot logs of ``benchmarks/discovery.py`` (start and complete events,
10 robots, a third of the activities exchanging messages, positions and batteries), written to
CSV first (untimed), in the same run, interleaved (robotale, pandas, robotale, pandas ...),
the best of ``--runs`` in wall time and in CPU time of the process:

- robotale: ``read_log_with_reading``, the whole reading every command does (the columns
  recognised, the missing markers, lifecycles and samples, copies, cases, robot types, the
  checks and the warnings);
- pandas: ``pandas.read_csv`` with pandas' own defaults and ``pandas.to_datetime`` on the time
  column, the least a reader of the file does before any of those rules.

The outputs are checked to hold the same rows, activities and times. Ratios above 1 mean
robotale takes longer than the baseline.
"""

from __future__ import annotations

import argparse
import os
import tempfile
import time
from pathlib import Path

import pandas as pd
from discovery import synthetic_log

from robotale.eventlog import schema
from robotale.eventlog.readers import read_log_with_reading


def robotale_read(path: Path) -> pd.DataFrame:
    return read_log_with_reading(path)[0]


def pandas_read(path: Path) -> pd.DataFrame:
    table = pd.read_csv(path)
    table[schema.TIMESTAMP] = pd.to_datetime(table[schema.TIMESTAMP], format="ISO8601")
    return table


def same(ours: pd.DataFrame, theirs: pd.DataFrame) -> bool:
    return (
        len(ours) == len(theirs)
        and ours[schema.ACTIVITY].astype(str).tolist() == theirs[schema.ACTIVITY].tolist()
        and (ours[schema.TIMESTAMP].to_numpy() == theirs[schema.TIMESTAMP].to_numpy()).all()
    )


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--sizes", type=int, nargs="+", default=[100_000])
    parser.add_argument("--runs", type=int, default=3)
    args = parser.parse_args()
    print(f"load average: {' '.join(f'{v:.2f}' for v in os.getloadavg())}")
    with tempfile.TemporaryDirectory(prefix="robotale-bench-read-") as scratch:
        for size in args.sizes:
            path = Path(scratch) / f"log_{size}.csv"
            synthetic_log(size).to_csv(path, index=False)
            runs = {"robotale": robotale_read, "pandas": pandas_read}
            wall = dict.fromkeys(runs, float("inf"))
            cpu = dict(wall)
            outputs = {}
            for _ in range(args.runs):
                for name, run in runs.items():
                    began, began_cpu = time.perf_counter(), time.process_time()
                    outputs[name] = run(path)
                    wall[name] = min(wall[name], time.perf_counter() - began)
                    cpu[name] = min(cpu[name], time.process_time() - began_cpu)
            print(
                f"{size:>9,} events: robotale {wall['robotale']:.2f} s (CPU "
                f"{cpu['robotale']:.2f} s), pandas {wall['pandas']:.2f} s (CPU "
                f"{cpu['pandas']:.2f} s); ratio {wall['robotale'] / wall['pandas']:.2f} wall, "
                f"{cpu['robotale'] / cpu['pandas']:.2f} CPU; same rows, activities and times: "
                f"{same(outputs['robotale'], outputs['pandas'])}"
            )
    print(f"load average: {' '.join(f'{v:.2f}' for v in os.getloadavg())}")


if __name__ == "__main__":
    main()
