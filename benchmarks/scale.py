"""How simulation and preparation scale out: a local process pool against a Dask cluster.

The agri batch (``--runs``, 200 by default) is simulated and then prepared into a Parquet
dataset partitioned by run, with 1, 2 and 4 workers (``--workers``) of each kind:

- ``local:N``: robotale's process pool of N processes (the baseline);
- ``dask``: a Dask ``LocalCluster`` of N single-threaded worker processes on loopback, the
  runs sent through its scheduler as to a cluster of machines (started before the clock runs,
  as a cluster is).

For each size it prints the wall time, the speed-up against one worker of the same kind, the
Dask time as a ratio of the pool's and Dask's overhead per run in milliseconds
((dask - pool) / runs), and the cost per run of one worker (wall time x workers / runs), the
figure docs/scale.md extrapolates from. Both kinds must give the same dataset: the rows per
run are compared.

    python benchmarks/scale.py [--runs 200] [--workers 1,2,4] [--time-limit 120]
                               [--ingest-events 100000 | --ingest-events 0]

Then, on a private Neo4j, one ingest of ``--ingest-events`` synthetic events (100k) against
an ingest of a tenth of its runs and nine ``ingest --append`` of a tenth each
(``compare_appends`` of benchmarks/ekg_build.py, the same synthetic log); 0 skips it.
"""

from __future__ import annotations

import argparse
import json
import tempfile
import time
import warnings
from collections.abc import Callable
from pathlib import Path

from robotale.eventlog.prepare import prepare_dataset
from robotale.sim.batch import simulate_batch
from robotale.sim.plans import adjust, plans, resolve_world


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--runs", type=int, default=200, help="agri runs (200)")
    parser.add_argument("--workers", default="1,2,4", help="worker counts to compare (1,2,4)")
    parser.add_argument(
        "--time-limit", type=float, help="simulated seconds a run may take (the world's)"
    )
    parser.add_argument(
        "--ingest-events", type=int, default=100_000, help="events of the ingest figure (0: none)"
    )
    args = parser.parse_args()
    warnings.simplefilter("ignore")
    sizes = [int(n) for n in args.workers.split(",") if n.strip()]
    world, _ = resolve_world("agri", None, None, None)
    if args.time_limit:
        world = adjust(world, time_limit=args.time_limit)
    batch = plans(world, "agri", runs=args.runs, seed=1)
    print(f"agri: {args.runs} runs, workers {sizes}, one process run")
    results: dict[tuple[str, int], dict[str, float]] = {}
    with tempfile.TemporaryDirectory(prefix="robotale-scale-") as scratch:
        for size in sizes:
            results["local", size] = measure(batch, Path(scratch) / f"local{size}", f"local:{size}")
            with dask_cluster(size) as address:
                results["dask", size] = measure(batch, Path(scratch) / f"dask{size}", address)
            same = results["local", size]["rows"] == results["dask", size]["rows"]
            print(f"  {size} worker(s): same dataset from both: {same}")
    report(results, sizes, args.runs)
    if args.ingest_events:
        ingest_figures(args.ingest_events)
    return 0


def measure(batch, folder: Path, executor: str) -> dict[str, float]:
    """Wall seconds to simulate the batch and to prepare it into a dataset on ``executor``."""
    simulated = timed(lambda: simulate_batch(batch, folder / "runs", executor=executor))
    prepared = timed(
        lambda: prepare_dataset(folder / "runs", folder / "agri.parquet", executor=executor)
    )
    manifest = json.loads((folder / "agri.parquet" / "_robotale_dataset.json").read_text())
    return {
        "simulate": simulated,
        "prepare": prepared,
        "rows": json.dumps([p["rows"] for p in manifest["parts"]]),
    }


def timed(work: Callable[[], object]) -> float:
    began = time.perf_counter()
    work()
    return time.perf_counter() - began


class dask_cluster:
    """A LocalCluster of ``size`` single-threaded worker processes; its scheduler's
    ``dask://`` address."""

    def __init__(self, size: int) -> None:
        self.size = size

    def __enter__(self) -> str:
        from distributed import LocalCluster

        began = time.perf_counter()
        self.cluster = LocalCluster(
            n_workers=self.size,
            threads_per_worker=1,
            processes=True,
            host="127.0.0.1",
            dashboard_address=":0",
        )
        print(f"  dask: {self.size} worker(s) up in {time.perf_counter() - began:.1f} s")
        return "dask://" + self.cluster.scheduler_address.removeprefix("tcp://")

    def __exit__(self, *exc: object) -> None:
        self.cluster.close()


def report(results: dict, sizes: list[int], runs: int) -> None:
    for step in ("simulate", "prepare"):
        print(
            f"\n{step}: wall s | speed-up vs 1 worker | dask/pool | dask overhead ms/run | "
            "worker-s per run"
        )
        for kind in ("local", "dask"):
            one = results.get((kind, sizes[0]), {}).get(step)
            for size in sizes:
                took = results[kind, size][step]
                pool = results["local", size][step]
                speed = f"{one * sizes[0] / took:.2f}x" if one else "-"
                print(
                    f"  {kind:5} {size}: {took:8.1f} | {speed:>6} | {took / pool:5.2f} | "
                    f"{(took - pool) / runs * 1000:7.1f} | {took * size / runs:6.2f}"
                )


def ingest_figures(events: int) -> None:
    """One ingest of ``events`` against ten parts, the first ingested and the others appended,
    on a Neo4j of its own (benchmarks/ekg_build.py owns the measurement)."""
    import sys

    sys.path.insert(0, str(Path(__file__).resolve().parent))
    import ekg_build

    print(f"\ningest: one log of {events:,} events vs ten parts, nine of them appended")
    with ekg_build.private_neo4j("2g") as driver:
        ekg_build.compare_appends(driver, events, parts=10)


if __name__ == "__main__":
    raise SystemExit(main())
