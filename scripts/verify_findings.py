"""Check robotale's answers against the simulation's truth on many generated missions.

    python scripts/verify_findings.py --seeds 500            # seeds 1..500, one run each
    python scripts/verify_findings.py --seeds 50 --first 1000 --workers 2 --out verify/

Each seed is a mission and world of its own (``robotale.sim.generate``), simulated with its
ground truth, prepared by ``robotale prepare`` and analysed by robotale; the oracle of
``tests/truth`` computes the true answers from the truth files alone. The script prints one
line per disagreement (seed, subject, case, item, the truth, robotale's answer), then the
disagreements per subject and the time per mission, and exits with 1 when there is any.
``make verify-findings SEEDS=N`` runs it.
"""

from __future__ import annotations

import argparse
import os
import shutil
import sys
import tempfile
import time
from collections import Counter
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path

# the oracle lives with the tests, apart from robotale, so that it cannot share its mistakes
sys.path.insert(0, str(Path(__file__).resolve().parent.parent / "tests" / "truth"))

import compare  # after the path above


def check(seed: int, root: Path, runs: int) -> tuple[int, list[list[str]], float, float, str]:
    """One seed: its disagreements, the seconds simulating and preparing took, the seconds the
    comparison took, and a crash's reason (empty when none)."""
    # imported here: each worker process imports the simulator once, the parent never needs it
    from robotale.sim.batch import simulate_batch
    from robotale.sim.generate import DELAY_THRESHOLD, generate
    from robotale.sim.plans import plans
    from robotale.sim.worldspec import load_world

    folder = root / f"seed_{seed}"
    began = time.perf_counter()
    mission = generate(seed, folder)
    batch = plans(load_world(mission.world), "generated", runs=runs, seed=seed)
    summary = simulate_batch(batch, folder / "runs", workers=0, overwrite=True)
    crashed = [c["reason"] for c in summary["cases"] if c["status"] == "crashed"]
    log = compare.prepared(folder / "runs")
    simulated = time.perf_counter() - began
    began = time.perf_counter()
    found = compare.disagreements(folder / "runs", log, DELAY_THRESHOLD)
    checked = time.perf_counter() - began
    return seed, [d.row(seed) for d in found], simulated, checked, "; ".join(crashed)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--seeds", type=int, default=50, help="how many seeds (50)")
    parser.add_argument("--first", type=int, default=1, help="the first seed (1)")
    parser.add_argument("--runs", type=int, default=1, help="runs per mission (1)")
    parser.add_argument("--workers", type=int, default=os.cpu_count() or 1)
    parser.add_argument("--out", type=Path, help="keep the missions and runs here")
    args = parser.parse_args(argv)
    root = args.out or Path(tempfile.mkdtemp(prefix="robotale-verify-"))
    seeds = range(args.first, args.first + args.seeds)
    rows = [["seed", "subject", "case", "item", "truth", "robotale"]]
    simulating = checking = 0.0
    crashes = []
    try:
        with ProcessPoolExecutor(max(1, args.workers)) as pool:
            futures = [pool.submit(check, seed, root, args.runs) for seed in seeds]
            for future in futures:
                seed, found, simulated, checked, crashed = future.result()
                rows += found
                simulating += simulated
                checking += checked
                if crashed:
                    crashes.append(f"seed {seed}: {crashed}")
    finally:
        if args.out is None:
            shutil.rmtree(root, ignore_errors=True)
    if len(rows) > 1:
        print(compare.table_text(rows))
        print()
    per_subject = Counter(row[1] for row in rows[1:])
    count = len(seeds)
    print(f"{count} missions, {len(rows) - 1} disagreements")
    for subject in compare.SUBJECTS:
        print(f"  {subject:<11} {per_subject.get(subject, 0)}")
    print(
        f"per mission: {simulating / count:.2f} s to simulate and prepare, "
        f"{checking / count:.2f} s to check against the truth"
    )
    for crash in crashes:
        print(f"crashed: {crash}")
    return 1 if len(rows) > 1 or crashes else 0


if __name__ == "__main__":
    sys.exit(main())
