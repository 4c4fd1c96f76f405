"""The findings report of this tree against an earlier revision's, on the same log.

    python benchmarks/findings_against.py REV [--sizes 10000 100000 1000000] [--runs 3]

``REV`` (a commit, a branch) is checked out into a temporary git worktree, removed afterwards.
The logs are the thesis' five runs repeated as further runs until they have the given number
of events, as ``report.py`` builds them (built once by this tree and handed to both sides as
the same pickled DataFrame). For each size, ``robotale.enhancement.findings.find`` runs on it
in separate Python processes, one tree's after the other's (A B A B ...), ``--runs`` times
each; each process first calls ``find`` on a small log, so imports and first calls stay out
of the figures. Printed: the load average before and after, each side's best wall-clock and
best CPU time of the process, and the ratio of this tree to ``REV`` (above 1: this tree is
slower; the target is at most 1.10 in CPU time).

What is checked equal between the two sides, and what is not: the revision may be one whose
answers mean something else (an interrupted activity later counted as an instance, a message
without a receive tag of its type later "not observed as received" rather than lost, resends
recognised by another rule, battery per robot and run, overlaps in space and time, bottlenecks
compared within completed runs). Compared: the number of runs, of variants and the median run
duration (the sequence answer), each activity's number of completed instances and their mean
and median duration per robot (the performance table; interrupted instances, which only this
tree counts, are left out of this tree's side), and the number of messages sent. Not compared:
received, lost, delayed and resent counts, bottleneck ranks and effects, battery use and the
robots' areas and encounters, whose rules the revision may not share.
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tempfile
import time
import warnings
from pathlib import Path

BENCHMARKS = Path(__file__).resolve().parent
ROOT = BENCHMARKS.parent
#: the size of the log each process analyses once before the timed call
WARM_UP_EVENTS = 2_000
#: relative difference below which two durations count as equal (the sums' rounding)
TOLERANCE = 1e-9


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("rev", help="the revision to compare with (a commit or branch)")
    parser.add_argument("--sizes", type=int, nargs="*", default=[10_000, 100_000, 1_000_000])
    parser.add_argument("--runs", type=int, default=3, help="processes per side and size (best)")
    parser.add_argument("--child", nargs=3, metavar=("TREE", "LOG", "WARM"), help=argparse.SUPPRESS)
    args = parser.parse_args()
    if args.child:
        print(json.dumps(child(*args.child)))
        return 0
    print("load average (1, 5, 15 min): " + load())
    with tempfile.TemporaryDirectory(prefix="robotale-bench-against-") as scratch:
        folder = Path(scratch)
        other = folder / "tree"
        subprocess.run(["git", "-C", str(ROOT), "worktree", "add", "--detach", "-q", str(other),
                        args.rev], check=True)  # fmt: skip
        try:
            warm = write_log(WARM_UP_EVENTS, folder)
            for size in args.sizes:
                measure(size, write_log(size, folder), warm, other, args)
        finally:
            subprocess.run(["git", "-C", str(ROOT), "worktree", "remove", "--force", str(other)],
                           check=True)  # fmt: skip
    print("load average after (1, 5, 15 min): " + load())
    return 0


def load() -> str:
    return ", ".join(f"{n:.1f}" for n in os.getloadavg())


def write_log(size: int, folder: Path) -> Path:
    sys.path.insert(0, str(BENCHMARKS))
    from dashboard import thesis_runs

    path = folder / f"runs_{size}.pkl"
    thesis_runs(size).to_pickle(path)
    return path


def measure(size: int, log: Path, warm: Path, other: Path, args) -> None:
    sides = {"this tree": ROOT, args.rev: other}
    times: dict[str, list[tuple[float, float]]] = {name: [] for name in sides}
    answers: dict[str, dict] = {}
    for _ in range(args.runs):
        for name, tree in sides.items():  # in turns: this tree, the revision, this tree ...
            result = run_child(tree, log, warm)
            times[name].append((result.pop("wall"), result.pop("cpu")))
            answers[name] = result
    print(f"== {size:,} events (best of {args.runs} processes each, in turns)")
    best = {name: (min(t[0] for t in ts), min(t[1] for t in ts)) for name, ts in times.items()}
    for name, (wall, cpu) in best.items():
        print(f"  {'find() of ' + name:40} {wall:7.2f} s wall, CPU {cpu:7.2f} s")
    (ours_wall, ours_cpu), (their_wall, their_cpu) = best["this tree"], best[args.rev]
    verdict = "met" if ours_cpu <= 1.10 * their_cpu else "MISSED"
    print(f"  {'this tree / ' + args.rev:40} {ours_wall / their_wall:7.2f}x wall, "
          f"CPU {ours_cpu / their_cpu:.2f}x (target <= 1.10x CPU: {verdict})")  # fmt: skip
    print("  check: " + compared(answers["this tree"], answers[args.rev]))
    print("  load average now: " + load())


def run_child(tree: Path, log: Path, warm: Path) -> dict:
    command = [sys.executable, str(Path(__file__).resolve()), "-", "--child", str(tree),
               str(log), str(warm)]  # fmt: skip
    # the tree's own package first; nothing else of this tree's on the path
    env = {**os.environ, "PYTHONPATH": str(tree)}
    done = subprocess.run(command, env=env, capture_output=True, text=True, check=False)
    if done.returncode:
        raise SystemExit(f"find() failed in {tree}:\n{done.stderr}")
    return json.loads(done.stdout.strip().splitlines()[-1])


def child(tree: str, log_path: str, warm_path: str) -> dict:
    """One process: ``tree``'s ``find`` on the log, timed once after a warm-up call."""
    warnings.simplefilter("ignore")
    sys.path.insert(0, tree)
    import pandas as pd

    import robotale
    from robotale.enhancement.findings import find

    if not Path(robotale.__file__).resolve().is_relative_to(Path(tree).resolve()):
        raise SystemExit(f"robotale was imported from {robotale.__file__}, not from {tree}")
    find(pd.read_pickle(warm_path))
    log = pd.read_pickle(log_path)
    wall, cpu = time.perf_counter(), time.process_time()
    findings = find(log)
    wall, cpu = time.perf_counter() - wall, time.process_time() - cpu
    return {"wall": wall, "cpu": cpu, **comparable(findings)}


def comparable(findings) -> dict:
    """What both revisions' answers mean alike (see the module's docstring)."""
    sequence = findings.answer("sequence").facts
    activities = findings.perspectives["performance"].tables["activities"]
    if "interrupted" in activities:  # completed instances only, as the earlier code counted
        activities = activities.assign(count=activities["count"] - activities["interrupted"])
    rows = sorted(
        [str(a), str(r), int(c), float(m), float(md)]
        for a, r, c, m, md in activities[
            ["activity", "robot", "count", "mean", "median"]
        ].itertuples(index=False)
    )
    return {
        "runs": sequence.get("runs"),
        "variants": sequence.get("variants"),
        "median_duration": sequence.get("median_duration"),
        "activities": rows,
        "sent": findings.answer("messages").facts.get("messages"),
    }


def compared(ours: dict, theirs: dict) -> str:
    differing = [key for key in ours if not same(ours[key], theirs.get(key))]
    summary = (
        f"{ours['runs']} runs, {ours['variants']} variants, {len(ours['activities'])} activity "
        f"rows, {ours['sent']} messages sent"
    )
    return f"equal ({summary})" if not differing else "DIFFERENT: " + ", ".join(differing)


def same(a, b) -> bool:
    if isinstance(a, list) and isinstance(b, list):
        return len(a) == len(b) and all(same(x, y) for x, y in zip(a, b, strict=True))
    if isinstance(a, float) and isinstance(b, float):
        return abs(a - b) <= TOLERANCE * max(abs(a), abs(b), 1.0)
    return a == b


if __name__ == "__main__":
    sys.exit(main())
