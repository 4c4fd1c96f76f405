"""How fast the simulator runs the agri scenario, headless, in kinematic and dynamics mode.

Both steps run once per mode, side by side: kinematic (poses set from the commands) and
dynamics (``dynamics: true``: ground robots with mass, forces and collisions, pybullet stepped
at the world's ``physics_rate``).

1. One agri run (drone + 2 tractors, the scenario's random weeds and batteries), recorded as a
   rosbag2: simulated seconds per wall second, against the wall clock itself (1x = real time),
   and simulated seconds per CPU second of this process (what other processes on a loaded
   machine distort least). Each run is timed ``--repeat`` times and its best time counts.
   Target: at least 50x real time.
2. A batch of agri runs (70 by default, as in thesis 7.2.1) on worker processes: its wall time,
   and its speed against running the same runs one after another in this process (projected
   from the single runs of step 1). Target: under 5 minutes on 2 cores.

    python benchmarks/sim_speed.py [--runs 70] [--single 5] [--repeat 3] [--workers N]
"""

from __future__ import annotations

import argparse
import dataclasses
import os
import statistics
import sys
import tempfile
import time
from pathlib import Path

from robotale.sim import scenarios
from robotale.sim.batch import run_into, simulate_batch
from robotale.sim.plans import adjust, plans
from robotale.sim.worldspec import load_world

SINGLE_TARGET = 50.0  # x real time
BATCH_TARGET = 300.0  # seconds


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--runs", type=int, default=70, help="runs in the batch (70)")
    parser.add_argument("--single", type=int, default=5, help="single runs to time (5)")
    parser.add_argument("--repeat", type=int, default=3, help="times each is timed, best (3)")
    parser.add_argument("--workers", type=int, default=os.cpu_count() or 1)
    args = parser.parse_args()
    world = adjust(load_world(scenarios.world_file("agri")), counts={"tractor": 2})
    for mode, dynamics in (("kinematic", False), ("dynamics", True)):
        print(f"-- {mode} mode")
        moded = dataclasses.replace(world, dynamics=dynamics)
        with tempfile.TemporaryDirectory(prefix="sim-speed-") as scratch:
            walls, simulated = single_runs(moded, Path(scratch), args.single, args.repeat)
            batch_runs(moded, Path(scratch) / "batch", args.runs, args.workers, walls, simulated)
    return 0


def single_runs(world, scratch: Path, count: int, repeat: int) -> tuple[list[float], list[float]]:
    """Each run's best wall and CPU time of ``repeat`` (a fresh folder each time)."""
    walls, cpus, simulated = [], [], []
    for plan in plans(world, "agri", runs=count, seed=1):
        times = []
        for attempt in range(repeat):
            folder = scratch / f"single_{attempt}"
            folder.mkdir(exist_ok=True)
            began, cpu = time.perf_counter(), time.process_time()
            manifest = run_into(plan, folder)
            times.append((time.perf_counter() - began, time.process_time() - cpu))
        walls.append(min(wall for wall, _ in times))
        cpus.append(min(cpu for _, cpu in times))
        simulated.append(manifest["duration"])
    factor, per_cpu = sum(simulated) / sum(walls), sum(simulated) / sum(cpus)
    verdict = "met" if factor >= SINGLE_TARGET else "NOT met"
    print(
        f"one agri run, headless, recorded ({count} runs, seed 1, best of {repeat}): "
        f"{statistics.mean(simulated):.1f} simulated s in {statistics.mean(walls):.3f} s wall "
        f"on average = {factor:.0f}x real time (target >= {SINGLE_TARGET:.0f}x: {verdict}); "
        f"{per_cpu:.0f} simulated s per CPU second; load average {os.getloadavg()[0]:.1f}"
    )
    return walls, simulated


def batch_runs(world, folder: Path, runs: int, workers: int, walls, simulated) -> None:
    began = time.perf_counter()
    summary = simulate_batch(plans(world, "agri", runs=runs, seed=1), folder, workers=workers)
    wall = time.perf_counter() - began
    outcomes = ", ".join(f"{n} {status}" for status, n in sorted(summary["outcomes"].items()))
    serial = summary["simulated_seconds"] / (sum(simulated) / sum(walls))
    verdict = "met" if wall < BATCH_TARGET else "NOT met"
    print(
        f"agri batch: {runs} runs on {summary['workers']} workers in {wall:.1f} s wall "
        f"(target < {BATCH_TARGET:.0f} s: {verdict}); {outcomes}; "
        f"load average {os.getloadavg()[0]:.1f}"
    )
    print(
        f"  {summary['simulated_seconds']:.0f} simulated s = "
        f"{summary['simulated_seconds'] / wall:.0f}x real time overall; "
        f"{serial / wall:.2f}x the speed of the same runs one after another in one process "
        f"(projected: {serial:.1f} s)"
    )


if __name__ == "__main__":
    sys.exit(main())
