"""The thesis' 70 agri runs (section 7.2) against robotale's calibrated agri scenario.

Simulates ``robotale simulate agri --thesis`` (70 runs by default, on worker processes),
prepares the bags into an event log (:func:`robotale.eventlog.prepare.prepare`) and prints, side
by side with the thesis' figures:

- messages per type, counted as the thesis' communication perspective counts them (7.2.2): a
  message is one ``msg_id`` of a run; sent if a robot performed its ``x!`` activity, received
  if any robot performed ``x?`` under that id, lost if sent and never received;
- weeds found per run (the drone's *weed found* activity), runs the drone ended on a low
  battery (it never threw ``field_cleaned!``, 7.2.2), the share of the field the drone's
  camera saw (the run manifests' ``coverage``);
- the drone's directly-follows edges the thesis describes for figure 7.4, present or absent.

The numbers are counted here from the log with pandas, independently of robotale's
communication perspective.

    python benchmarks/thesis_reproduction.py [--runs 70] [--seed 1] [--workers N] [--out DIR]
"""

from __future__ import annotations

import argparse
import itertools
import os
import statistics
import sys
import tempfile
import time
from pathlib import Path

import pandas as pd

from robotale.eventlog.prepare import prepare
from robotale.eventlog.schema import ACTIVITY, CASE, LIFECYCLE, MSG_ID, ROBOT, START, TIMESTAMP
from robotale.fame_runtime.manifest import read_manifests
from robotale.sim.batch import simulate_batch
from robotale.sim.plans import plans, resolve_world

THESIS_RUNS = 70
#: section 7.2.2: per message type, (sent, received, lost) over the 70 runs
THESIS_MESSAGES = {
    "weed_position": (1748, 1414, 334),
    "tractor_position": (1816, 1816, 0),
    "closest_tractor": (1080, 1080, 0),
}
#: the thesis' ten drone activities (7.2.1) as robotale's agri tags them
DRONE_ACTIVITIES = {
    "take_off",
    "explore",
    "weed_found",
    "weed_position!",
    "tractor_position?",
    "closest_tractor!",
    "low_battery",
    "field_cleaned!",
    "return_to_base",
    "land",
}
#: the drone's process as section 7.2.2 describes figure 7.4
FIGURE_7_4 = [
    ("take_off", "explore"),
    ("explore", "weed_found"),
    ("weed_found", "weed_position!"),
    ("weed_position!", "tractor_position?"),
    ("tractor_position?", "closest_tractor!"),
    ("closest_tractor!", "explore"),
    ("explore", "low_battery"),
    ("low_battery", "return_to_base"),
    ("return_to_base", "land"),
]
TOLERANCE = 0.25  # the share by which a message count may differ from the thesis'


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--runs", type=int, default=THESIS_RUNS, help="runs to simulate (70)")
    parser.add_argument("--seed", type=int, default=1, help="the batch's seed (1)")
    parser.add_argument("--workers", type=int, default=os.cpu_count() or 1)
    parser.add_argument("--out", type=Path, help="keep the runs here (default: a scratch folder)")
    args = parser.parse_args()
    if args.out is not None:
        return report(args.out, args.runs, args.seed, args.workers)
    with tempfile.TemporaryDirectory(prefix="thesis-") as scratch:
        return report(Path(scratch) / "agri", args.runs, args.seed, args.workers)


def report(out: Path, runs: int, seed: int, workers: int) -> int:
    world, _ = resolve_world("agri", preset="thesis")
    began = time.perf_counter()
    summary = simulate_batch(plans(world, "agri", runs=runs, seed=seed), out, workers=workers)
    simulated = time.perf_counter() - began
    began = time.perf_counter()
    log = prepare(out)
    prepared = time.perf_counter() - began
    print(
        f"{runs} runs of agri --thesis (seed {seed}) simulated in {simulated:.0f} s on "
        f"{summary['workers']} workers ({summary['simulated_seconds'] / runs:.0f} simulated s "
        f"a run), prepared in {prepared:.0f} s; load average {os.getloadavg()[0]:.1f}"
    )
    scale = runs / THESIS_RUNS
    print(f"\nmessages (thesis' counts scaled by {runs}/{THESIS_RUNS} runs)\n")
    table = message_counts(log)
    ok = print_messages(table, scale)
    print("\nthe runs\n")
    print_runs(log, out)
    print("\nthe drone's DFG (figure 7.4)\n")
    print_figure(log)
    return 0 if ok else 1


def message_counts(log: pd.DataFrame) -> pd.DataFrame:
    """Per message type: sent, received and lost messages (one message = a case and msg_id)."""
    events = log[log[MSG_ID].notna()]
    activity = events[ACTIVITY].astype(str)
    rows = {}
    for name in THESIS_MESSAGES:
        sent = set(_ids(events[activity == f"{name}!"]))
        received = set(_ids(events[activity == f"{name}?"]))
        rows[name] = {
            "sent": len(sent),
            "received": len(sent & received),
            "lost": len(sent - received),
        }
    return pd.DataFrame.from_dict(rows, orient="index")


def _ids(events: pd.DataFrame) -> list[tuple[str, str]]:
    return list(zip(events[CASE].astype(str), events[MSG_ID].astype(str), strict=True))


def print_messages(table: pd.DataFrame, scale: float) -> bool:
    print("| message | thesis sent / received / lost | robotale sent / received / lost | sent |")
    print("|---|---|---|---|")
    within = True
    for name, (sent, received, lost) in THESIS_MESSAGES.items():
        mine = table.loc[name]
        ratio = mine["sent"] / (sent * scale)
        within &= abs(ratio - 1) <= TOLERANCE
        print(
            f"| `{name}` | {sent * scale:.0f} / {received * scale:.0f} / {lost * scale:.0f} | "
            f"{mine['sent']} / {mine['received']} / {mine['lost']} | {ratio:.2f}x |"
        )
    mine = table.loc["weed_position"]
    print(
        f"\nweed_position lost: thesis {334 / 1748:.1%}, robotale "
        f"{mine['lost'] / max(1, mine['sent']):.1%}; every count within {TOLERANCE:.0%}: "
        f"{'yes' if within else 'NO'}"
    )
    return within


def print_runs(log: pd.DataFrame, out: Path) -> None:
    drone = log[(log[ROBOT] == "drone") & (log[LIFECYCLE] == START)]
    per_case = drone.groupby(CASE)[ACTIVITY].agg(set)
    found = drone[drone[ACTIVITY] == "weed_found"].groupby(CASE).size()
    found = found.reindex(per_case.index, fill_value=0)
    low = sum("low_battery" in acts and "field_cleaned!" not in acts for acts in per_case)
    manifests = read_manifests(sorted(p for p in out.glob("run_*") if p.is_dir()))
    seen = [m["coverage"]["seen"]["drone"] for m in manifests.values() if "coverage" in m]
    total = [m["weeds"]["total"] for m in manifests.values() if "weeds" in m]
    runs = len(per_case)
    print("| | thesis | robotale |")
    print("|---|---|---|")
    print(
        f"| runs the drone ended on a low battery | 70 of 70 | {low} of {runs} |\n"
        f"| weeds found per run (mean, min-max) | 15.4 assigned (1080 / 70) | "
        f"{found.mean():.1f} ({found.min()}-{found.max()}) of {statistics.mean(total):.0f} |\n"
        f'| field the drone\'s camera saw (mean, min-max) | "most of the field" unexplored | '
        f"{statistics.mean(seen):.0%} ({min(seen):.0%}-{max(seen):.0%}) |"
    )


def print_figure(log: pd.DataFrame) -> None:
    edges = drone_edges(log)
    print("| edge | thesis | robotale (runs with it) |")
    print("|---|---|---|")
    for edge in FIGURE_7_4:
        print(f"| {edge[0]} -> {edge[1]} | present | {edges.get(edge, 0)} |")
    cleaned = sum(n for (a, b), n in edges.items() if "field_cleaned!" in (a, b))
    print(f"| field_cleaned! (any edge) | absent | {cleaned} |")


def drone_edges(log: pd.DataFrame) -> dict[tuple[str, str], int]:
    """The drone's directly-follows edges over the thesis' activities (each instance's start),
    with the number of runs that have each."""
    drone = log[
        (log[ROBOT] == "drone") & (log[LIFECYCLE] == START) & log[ACTIVITY].isin(DRONE_ACTIVITIES)
    ].sort_values([CASE, TIMESTAMP], kind="stable")
    edges: dict[tuple[str, str], set[str]] = {}
    for case, activities in drone.groupby(CASE)[ACTIVITY]:
        steps = activities.tolist()
        for edge in itertools.pairwise(steps):
            edges.setdefault(edge, set()).add(str(case))
    return {edge: len(cases) for edge, cases in edges.items()}


if __name__ == "__main__":
    sys.exit(main())
