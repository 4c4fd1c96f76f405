"""A batch of runs spread over worker processes, one rosbag2 directory per run.

:func:`simulate_batch` writes ``<out>/run_0001/`` ... (each a bag with its
``robotale-run.json``) and ``<out>/robotale-batch.json``, the batch's summary. A run is
recorded inside a hidden ``.run_0001.partial`` folder and moved into place when complete, so
``<out>`` never holds half a bag (and the bag's files carry the run's own name). A run that
raises is recorded as crashed and the batch goes on; a run that kills its worker process is
retried alone once, then recorded as crashed (a manifest without a bag).

The runs go to the executor ``--executor`` names (:mod:`robotale.executors`): a local process
pool, or a Dask cluster whose workers write into ``out`` themselves, so ``out`` must be a
folder every worker reaches at the same path (a shared folder). On Dask a run whose worker
died is retried by the scheduler (``distributed.scheduler.allowed-failures``), then recorded
as crashed.
"""

from __future__ import annotations

import json
import shutil
import time
from collections import Counter
from collections.abc import Callable, Iterable, Sequence
from concurrent.futures import Future, as_completed
from dataclasses import replace
from pathlib import Path
from typing import Any

from tqdm import tqdm

from robotale.errors import InputError
from robotale.executors import ExecutorSpec, open_executor, parse_executor, worker_lost
from robotale.fame_runtime.manifest import RunManifest, read_manifest, write_manifest
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
    executor: str | ExecutorSpec | None = None,
) -> dict[str, Any]:
    """Simulate every run of ``plans`` into ``out``; returns the batch summary.

    ``workers`` processes run them (default: one per CPU, at most one per run; 0 runs them in
    this process); ``executor`` (``local:N``, ``dask://HOST:PORT``) names where else they go.
    ``overwrite`` replaces the runs of an earlier batch in ``out``. With ``gui`` (pybullet's
    window) or ``pace`` (simulated seconds per wall second) the runs go one after the other in
    this process, for a person to watch.
    """
    spec = executor if isinstance(executor, ExecutorSpec) else parse_executor(executor, workers)
    # absolute: a Dask worker's working folder is not ours
    out = Path(out).resolve() if spec.remote else Path(out)
    prepare_folder(out, overwrite)
    began = time.perf_counter()
    here = gui or pace or spec.workers == 0 or (len(plans) == 1 and not spec.remote)
    workers = 0
    manifests: dict[str, RunManifest] = {}
    with tqdm(
        total=len(plans), unit="run", desc="simulate", disable=not progress, leave=False
    ) as bar:

        def finished(manifest: RunManifest) -> None:
            manifests[manifest["case"]] = manifest
            bar.update()
            bar.set_postfix(Counter(m["outcome"]["status"] for m in manifests.values()))

        try:
            if here:
                for plan in plans:
                    finished(run_into(plan, out, gui=gui, pace=pace))
            else:
                workers = _in_pool(plans, out, spec, finished)
        except BaseException:
            _remove_partials(out)
            raise
    summary = _summary(plans, [manifests[p.case] for p in plans], workers, began)
    if spec.remote:
        summary["executor"] = spec.describe()
    write_file(out / SUMMARY, json.dumps(summary, indent=2) + "\n")
    return summary


def run_into(
    plan: RunPlan, out: Path, *, gui: bool = False, pace: float | None = None
) -> RunManifest:
    """One run recorded into ``out/<case>`` (through a hidden partial folder)."""
    # rosbag2 names its storage files after the bag's folder, so the bag is written under its
    # final name inside the hidden folder and only the folder is moved.
    partial, final = out / f".{plan.case}.partial", out / plan.case
    # A Dask cluster runs a finished run again when the worker holding its result dies, even
    # after the batch has taken the result; the run is deterministic and its folder only
    # appears whole, so a second attempt hands back the first's manifest and touches nothing.
    if (done := read_manifest(final)) is not None:
        return done
    shutil.rmtree(partial, ignore_errors=True)
    partial.mkdir(parents=True)
    try:
        manifest = simulate_run(plan, partial / plan.case, gui=gui, pace=pace)
        try:
            (partial / plan.case).rename(final)
        except OSError:
            # another attempt of the same run got there first (a worker Dask thought lost)
            if (done := read_manifest(final)) is None:
                raise
            return done
    finally:
        shutil.rmtree(partial, ignore_errors=True)
    return manifest


Finished = Callable[[RunManifest], None]


def _in_pool(plans: Sequence[RunPlan], out: Path, spec: ExecutorSpec, finished: Finished) -> int:
    """Run ``plans`` on the executor; returns how many workers it had."""
    broken, workers = _pool_round(plans, out, spec, finished)
    for plan in broken:
        # Dask already retried it on other workers; a local pool breaks as a whole, so the
        # run goes alone into a fresh pool to pin the crash on its run.
        if spec.remote or _pool_round([plan], out, replace(spec, workers=1), finished)[0]:
            finished(_died(plan, out))
    return workers


def _pool_round(
    plans: Sequence[RunPlan], out: Path, spec: ExecutorSpec, finished: Finished
) -> tuple[list[RunPlan], int]:
    """Run ``plans`` on the executor; returns those lost when a worker process died, and how
    many workers there were."""
    lost: list[RunPlan] = []
    with open_executor(spec, len(plans)) as (pool, workers):
        futures: dict[Future, RunPlan] = {pool.submit(run_into, p, out): p for p in plans}
        try:
            for future in as_completed(futures):
                try:
                    finished(future.result())
                except Exception as error:
                    if not worker_lost(error):
                        raise
                    lost.append(futures[future])
        except BaseException:
            for future in futures:
                future.cancel()
            raise
    return sorted(lost, key=lambda p: p.index), workers


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
