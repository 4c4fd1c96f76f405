"""``robotale simulate``: a batch of simulated runs (or one run in pybullet's window)."""

from __future__ import annotations

import os
import sys
from collections.abc import Sequence
from pathlib import Path
from typing import Any, TextIO

from robotale.errors import InputError
from robotale.sim.batch import simulate_batch
from robotale.sim.plans import adjust, check, plans, resolve_world


def simulate_command(
    scenario: str | None = None,
    *,
    model: Path | None = None,
    world: Path | None = None,
    library: Path | None = None,
    thesis: bool = False,
    runs: int = 1,
    seed: int = 1,
    first: int = 1,
    out_dir: Path | None = None,
    tractors: int | None = None,
    counts: Sequence[str] = (),
    weeds: str | None = None,
    faults: Sequence[str] = (),
    storage: str = "sqlite3",
    distro: str = "humble",
    rate: float | None = None,
    topics: str | None = None,
    time_limit: float | None = None,
    workers: int | None = None,
    executor: str | None = None,
    gui: bool = False,
    pace: float | None = None,
    overwrite: bool = False,
    quiet: bool = False,
    out: TextIO | None = None,
) -> int:
    """A batch of ``runs`` runs recorded under ``out_dir`` (``runs/<scenario>``); with ``gui``
    one run in pybullet's window at ``pace`` simulated seconds per wall second. ``executor``
    (``local[:N]``, ``dask://HOST:PORT``) says where the runs go; ``thesis`` takes the
    scenario's world calibrated to the thesis."""
    out = out or sys.stdout
    preset = "thesis" if thesis else None
    loaded, scenario = resolve_world(scenario, model, world, library, preset=preset)
    group_counts = dict(_count(text) for text in counts)
    if tractors is not None:
        group_counts["tractor"] = tractors
    loaded = adjust(
        loaded,
        counts=group_counts,
        weeds=_weeds(weeds) if weeds else None,
        time_limit=time_limit,
        rate=rate,
    )
    missing = check(loaded)
    if missing:  # before anything runs, like fame check --world
        print(f"simulation lacks: {len(missing)}", file=out)
        for sentence in missing:
            print(f"  {sentence}", file=out)
    overrides = {
        "counts": dict(_count(text) for text in counts) or None,
        "tractors": tractors,
        "weeds": weeds,
        "faults": list(faults) or None,
        "extra_topics": _topics(topics) or None,
    }
    batch = plans(
        loaded,
        scenario,
        runs=runs,
        seed=seed,
        first=first,
        faults=faults,
        storage=storage,
        extra_topics=_topics(topics),
        settings={key: value for key, value in overrides.items() if value is not None},
        distro=distro,
    )
    target = out_dir or Path("runs") / scenario
    if gui and not (os.environ.get("DISPLAY") or os.environ.get("WAYLAND_DISPLAY")):
        raise InputError("--gui needs a display (DISPLAY is not set); run without --gui")
    watching = gui or bool(pace)
    summary = simulate_batch(
        batch,
        target,
        workers=workers,
        executor=executor,
        overwrite=overwrite,
        progress=not (quiet or watching),
        gui=gui,
        pace=(pace or 1.0) if watching else None,
    )
    print_summary(summary, target, out)
    return 0


def print_summary(summary: dict[str, Any], target: Path, out: TextIO) -> None:
    outcomes = ", ".join(f"{n} {status}" for status, n in sorted(summary["outcomes"].items()))
    runs, workers = summary["runs"], summary["workers"]
    where = f"{workers} worker{'s' if workers != 1 else ''}" if workers else "in this process"
    if "executor" in summary:
        where += f" on {summary['executor']}"
    print(
        f"{runs} run{'s' if runs != 1 else ''} of {summary['scenario']} "
        f"in {summary['wall_time']:.1f} s ({where}): {outcomes}",
        file=out,
    )
    for case in summary["cases"]:
        if case["status"] != "ended":
            reason = f": {case['reason']}" if case["reason"] else ""
            print(f"  {case['case']} {case['status']}{reason}", file=out)
    for kind, verb in (("weeds", "cut"), ("targets", "destroyed")):
        totals = [c[kind] for c in summary["cases"] if kind in c]
        if totals:
            done = sum(t[verb] for t in totals)
            print(f"{kind}: {done} of {sum(t['total'] for t in totals)} {verb}", file=out)
    print(f"recorded in {target} (summary: {target / 'robotale-batch.json'})", file=out)


def _count(text: str) -> tuple[str, int]:
    group, sep, number = text.partition("=")
    if not sep or not number.strip().isdigit():
        raise InputError(f"--count {text!r} must be GROUP=N, e.g. tractor=3")
    return group.strip(), int(number)


def _weeds(text: str) -> tuple[int, int]:
    low, _, high = text.partition("-")
    if not low.strip().isdigit() or (high and not high.strip().isdigit()):
        raise InputError(f"--weeds {text!r} must be a number or LOW-HIGH, e.g. 2 or 3-6")
    bounds = (int(low), int(high or low))
    if bounds[1] < bounds[0]:
        raise InputError(f"--weeds {text!r}: the range ends before it starts")
    return bounds


def _topics(text: str | None) -> list[str]:
    return [t.strip().strip("/") for t in text.split(",") if t.strip()] if text else []
