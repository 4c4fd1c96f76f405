"""A batch of runs spread over worker processes, one rosbag2 directory per run.

:func:`simulate_batch` writes ``<out>/run_0001/`` ... (each a bag with its
``robotale-run.json``) and ``<out>/robotale-batch.json``, the batch's summary. A run is
recorded inside a hidden ``.run_0001.partial`` folder and moved into place when complete, so
``<out>`` never holds half a bag (and the bag's files carry the run's own name). A run that
raises is recorded as crashed and the batch goes on; a run that kills its worker process is
retried alone once, then recorded as crashed (a manifest without a bag).
"""

from __future__ import annotations

import json
import multiprocessing
import os
import shutil
import time
from collections import Counter
from collections.abc import Iterable, Sequence
from concurrent.futures import Future, ProcessPoolExecutor, as_completed
from concurrent.futures.process import BrokenProcessPool
from pathlib import Path
from typing import Any

from tqdm import tqdm

from robotale.errors import InputError
from robotale.fame_runtime.manifest import RunManifest, write_manifest
from robotale.files import write_file
from robotale.sim import scenarios
from robotale.sim.run import CRASHED, RunPlan, simulate_run

SUMMARY = "robotale-batch.json"


def simulate_batch(
    plans: Sequence[RunPlan],
    out: str | Path,
    *,
    workers: int | None = None,
    overwrite: bool = False,
    progress: bool = False,
    gui: bool = False,
    pace: float | None = None,
) -> dict[str, Any]:
    """Simulate every run of ``plans`` into ``out``; returns the batch summary.

    ``workers`` processes run them (default: one per CPU, at most one per run; 0 runs them in
    this process). ``overwrite`` replaces the runs of an earlier batch in ``out``. With ``gui``
    (pybullet's window) or ``pace`` (simulated seconds per wall second) the runs go one after
    the other in this process, for a person to watch.
    """
    out = Path(out)
    prepare_folder(out, overwrite)
    began = time.perf_counter()
    if workers is None:
        workers = os.cpu_count() or 1
    workers = 0 if gui or pace or len(plans) == 1 else min(workers, len(plans))
    manifests: dict[str, RunManifest] = {}
    with tqdm(
        total=len(plans), unit="run", desc="simulate", disable=not progress, leave=False
    ) as bar:

        def finished(manifest: RunManifest) -> None:
            manifests[manifest["case"]] = manifest
            bar.update()
            bar.set_postfix(Counter(m["outcome"]["status"] for m in manifests.values()))

        try:
            if workers == 0:
                for plan in plans:
                    finished(run_into(plan, out, gui=gui, pace=pace))
            else:
                _in_pool(plans, out, workers, finished)
        except BaseException:
            _remove_partials(out)
            raise
    summary = _summary(plans, [manifests[p.case] for p in plans], workers, began)
    write_file(out / SUMMARY, json.dumps(summary, indent=2) + "\n")
    return summary


def run_into(
    plan: RunPlan, out: Path, *, gui: bool = False, pace: float | None = None
) -> RunManifest:
    """One run recorded into ``out/<case>`` (through a hidden partial folder)."""
    # rosbag2 names its storage files after the bag's folder, so the bag is written under its
    # final name inside the hidden folder and only the folder is moved.
    partial, final = out / f".{plan.case}.partial", out / plan.case
    shutil.rmtree(partial, ignore_errors=True)
    partial.mkdir(parents=True)
    try:
        manifest = simulate_run(plan, partial / plan.case, gui=gui, pace=pace)
        (partial / plan.case).rename(final)
    finally:
        shutil.rmtree(partial, ignore_errors=True)
    return manifest


def _in_pool(plans: Sequence[RunPlan], out: Path, workers: int, finished) -> None:
    broken = _pool_round(plans, out, workers, finished)
    for plan in broken:  # alone in a fresh worker, so a crash is pinned on its run
        if _pool_round([plan], out, 1, finished):
            finished(_died(plan, out))


def _pool_round(plans: Sequence[RunPlan], out: Path, workers: int, finished) -> list[RunPlan]:
    """Run ``plans`` in a pool; returns those lost when a worker process died."""
    context = multiprocessing.get_context("spawn")
    lost: list[RunPlan] = []
    with ProcessPoolExecutor(max_workers=workers, mp_context=context) as pool:
        futures: dict[Future, RunPlan] = {pool.submit(run_into, p, out): p for p in plans}
        try:
            for future in as_completed(futures):
                try:
                    finished(future.result())
                except BrokenProcessPool:
                    lost.append(futures[future])
        except BaseException:
            pool.shutdown(wait=False, cancel_futures=True)
            raise
    return sorted(lost, key=lambda p: p.index)


def _died(plan: RunPlan, out: Path) -> RunManifest:
    """The manifest of a run whose worker process died: no bag, the reason."""
    shutil.rmtree(out / f".{plan.case}.partial", ignore_errors=True)
    manifest: RunManifest = {
        "case": plan.case,
        "scenario": plan.scenario,
        "seed": plan.seed,
        "batch_seed": plan.batch_seed,
        "index": plan.index,
        "outcome": {
            "status": CRASHED,
            "reason": "the worker process running it died (a fault in native code or an "
            "exit called by the model)",
        },
    }
    folder = out / plan.case
    folder.mkdir(parents=True, exist_ok=True)
    write_manifest(folder, manifest)
    return manifest


def prepare_folder(out: Path, overwrite: bool) -> None:
    if out.exists() and not out.is_dir():
        raise InputError(f"{out} is a file; --out needs a folder for the runs")
    earlier = _earlier_runs(out)
    if earlier and not overwrite:
        raise InputError(
            f"{out} already holds recorded runs ({earlier[0].name} ...); choose another --out "
            "or pass --overwrite to replace them"
        )
    for path in earlier:
        shutil.rmtree(path) if path.is_dir() else path.unlink()
    out.mkdir(parents=True, exist_ok=True)
    _remove_partials(out)


def _earlier_runs(out: Path) -> list[Path]:
    if not out.is_dir():
        return []
    found = sorted(p for p in out.glob("run_*") if p.is_dir())
    return found + ([out / SUMMARY] if (out / SUMMARY).exists() else [])


def _remove_partials(out: Path) -> None:
    for partial in out.glob(".run_*.partial"):
        shutil.rmtree(partial, ignore_errors=True)


def _summary(
    plans: Sequence[RunPlan], manifests: Iterable[RunManifest], workers: int, began: float
) -> dict[str, Any]:
    manifests = list(manifests)
    first = plans[0]
    return {
        "scenario": first.scenario,
        "model": scenarios.describe(first.world.model),
        "world": scenarios.describe(first.world.file),
        "seed": first.batch_seed,
        "runs": len(manifests),
        "workers": workers,
        "wall_time": round(time.perf_counter() - began, 3),
        "outcomes": dict(Counter(m["outcome"]["status"] for m in manifests)),
        "simulated_seconds": round(sum(m.get("duration", 0.0) for m in manifests), 3),
        "cases": [_line(m) for m in manifests],
    }


def _line(manifest: RunManifest) -> dict[str, Any]:
    line = {
        "case": manifest["case"],
        "seed": manifest["seed"],
        "status": manifest["outcome"]["status"],
        "reason": manifest["outcome"]["reason"],
        "duration": manifest.get("duration"),
    }
    for kind in ("weeds", "targets"):
        if kind in manifest:
            line[kind] = manifest[kind]
    return line
