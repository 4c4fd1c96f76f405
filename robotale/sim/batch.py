"""A batch of runs spread over worker processes, one rosbag2 directory per run.

:func:`simulate_batch` writes ``<out>/run_0001/`` ... (each a bag with its
``robotale-run.json``) and ``<out>/robotale-batch.json``, the batch's summary. A run is
recorded inside a hidden ``.run_0001.partial`` folder and moved into place when complete, so
``<out>`` never holds half a bag (and the bag's files carry the run's own name). A run that
raises is recorded as crashed and the batch goes on; a run that kills its worker process is
retried alone once, then recorded as crashed (a manifest without a bag).

The runs go to the executor ``--executor`` names (:mod:`robotale.executors`): a local process
pool, or a Dask cluster whose workers write into ``out`` themselves, so ``out`` must be a
folder every worker reaches at the same path (a shared folder), or an fsspec URL
(:mod:`robotale.storage`): then each run is recorded in a local temporary folder of its worker
and uploaded whole, through a hidden ``.run_0001.partial`` moved into place. On Dask a run
whose worker died is retried by the scheduler (``distributed.scheduler.allowed-failures``),
then recorded as crashed.
"""

from __future__ import annotations

import fnmatch
import json
import shutil
import tempfile
import time
from collections import Counter
from collections.abc import Callable, Iterable, Sequence
from concurrent.futures import Future, as_completed
from dataclasses import replace
from pathlib import Path
from typing import Any, TextIO

from tqdm import tqdm

from robotale.errors import InputError
from robotale.executors import (
    ExecutorSpec,
    open_executor,
    parse_executor,
    stop_all,
    worker_lost,
)
from robotale.fame_runtime.manifest import (
    MANIFEST,
    RunManifest,
    manifest_text,
    parse_manifest,
    read_manifest,
    write_manifest,
)
from robotale.files import write_file
from robotale.sim import scenarios
from robotale.sim.run import CRASHED, RunPlan, Watch, simulate_run
from robotale.storage import Place, local_path, place, upload_folder, writing

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
    watch: Watch | None = None,
) -> dict[str, Any]:
    """Simulate every run of ``plans`` into ``out``; returns the batch summary.

    ``workers`` processes run them (default: one per CPU, at most one per run; 0 runs them in
    this process); ``executor`` (``local:N``, ``dask://HOST:PORT``) names where else they go.
    ``overwrite`` replaces the runs of an earlier batch in ``out``. With ``gui`` (pybullet's
    window), ``pace`` (simulated seconds per wall second) or ``watch`` (the monitor, watching
    each run as it goes) the runs go one after the other in this process.
    """
    spec = executor if isinstance(executor, ExecutorSpec) else parse_executor(executor, workers)
    local = local_path(out)
    # absolute: a Dask worker's working folder is not ours
    where: Path | Place = place(out) if local is None else local.resolve() if spec.remote else local
    _prepare_destination(where, overwrite)
    began = time.perf_counter()
    here = (
        gui
        or pace
        or watch is not None
        or spec.workers == 0
        or (len(plans) == 1 and not spec.remote)
    )
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
                    finished(_run(plan, where, gui=gui, pace=pace, watch=watch))
            else:
                workers = _in_pool(plans, where, spec, finished)
        except BaseException:
            _remove_partials(where)
            raise
    summary = _summary(plans, [manifests[p.case] for p in plans], workers, began)
    if spec.remote:
        summary["executor"] = spec.describe()
    text = json.dumps(summary, indent=2) + "\n"
    if isinstance(where, Place):
        where.child(SUMMARY).write_whole(text)
    else:
        write_file(where / SUMMARY, text)
    return summary


def _run(
    plan: RunPlan,
    where: Path | Place,
    *,
    gui: bool = False,
    pace: float | None = None,
    watch: Watch | None = None,
) -> RunManifest:
    """One run recorded into a local folder, or recorded here and uploaded to a place."""
    if isinstance(where, Place):
        return run_uploaded(plan, where, gui=gui, pace=pace, watch=watch)
    return run_into(plan, where, gui=gui, pace=pace, watch=watch)


def run_uploaded(
    plan: RunPlan,
    target: Place,
    *,
    gui: bool = False,
    pace: float | None = None,
    watch: Watch | None = None,
) -> RunManifest:
    """One run recorded in a local temporary folder (rosbag2 writes local files only), then
    uploaded as ``target/<case>`` through a hidden folder moved into place."""
    final = target.child(plan.case)
    if (done := _remote_manifest(final)) is not None:  # a late second attempt, as in run_into
        return done
    with tempfile.TemporaryDirectory(prefix="robotale-run-") as folder:
        manifest = run_into(plan, Path(folder), gui=gui, pace=pace, watch=watch)
        try:
            upload_folder(Path(folder) / plan.case, final)
        except Exception:  # ftplib's refusals are no OSError
            # another attempt of the same run got there first (a worker Dask thought lost)
            if (done := _remote_manifest(final)) is None:
                raise
            return done
    return manifest


def _remote_manifest(run: Place) -> RunManifest | None:
    found = run.child(MANIFEST)
    return parse_manifest(found.read_bytes(), found.text) if found.exists() else None


def run_into(
    plan: RunPlan,
    out: Path,
    *,
    gui: bool = False,
    pace: float | None = None,
    watch: Watch | None = None,
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
        manifest = simulate_run(plan, partial / plan.case, gui=gui, pace=pace, watch=watch)
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


def _in_pool(
    plans: Sequence[RunPlan], out: Path | Place, spec: ExecutorSpec, finished: Finished
) -> int:
    """Run ``plans`` on the executor; returns how many workers it had."""
    broken, workers = _pool_round(plans, out, spec, finished)
    for plan in broken:
        # Dask already retried it on other workers; a local pool breaks as a whole, so the
        # run goes alone into a fresh pool to pin the crash on its run.
        if spec.remote or _pool_round([plan], out, replace(spec, workers=1), finished)[0]:
            finished(_died(plan, out))
    return workers


def _pool_round(
    plans: Sequence[RunPlan], out: Path | Place, spec: ExecutorSpec, finished: Finished
) -> tuple[list[RunPlan], int]:
    """Run ``plans`` on the executor; returns those lost when a worker process died, and how
    many workers there were."""
    lost: list[RunPlan] = []
    with open_executor(spec, len(plans)) as (pool, workers):
        futures: dict[Future, RunPlan] = {pool.submit(_run, p, out): p for p in plans}
        try:
            for future in as_completed(futures):
                try:
                    finished(future.result())
                except Exception as error:
                    if not worker_lost(error):
                        raise
                    lost.append(futures[future])
        except BaseException as error:
            stop_all(futures, error)
            raise
    return sorted(lost, key=lambda p: p.index), workers


def _died(plan: RunPlan, out: Path | Place) -> RunManifest:
    """The manifest of a run whose worker process died: no bag, the reason."""
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
    if isinstance(out, Place):
        out.child(f".{plan.case}.partial").remove()
        out.child(plan.case, MANIFEST).write_whole(manifest_text(manifest))
        return manifest
    shutil.rmtree(out / f".{plan.case}.partial", ignore_errors=True)
    folder = out / plan.case
    folder.mkdir(parents=True, exist_ok=True)
    write_manifest(folder, manifest)
    return manifest


def _prepare_destination(where: Path | Place, overwrite: bool) -> None:
    """Refuse a destination holding an earlier batch unless ``overwrite`` (then remove its
    runs); create it; remove the partial runs an interrupted batch left."""
    out = where if isinstance(where, Place) else place(where)
    with writing(out):
        _empty_destination(out, overwrite)


def _empty_destination(out: Place, overwrite: bool) -> None:
    if out.exists() and not out.is_dir():
        raise InputError(f"{out.text} is a file; --out needs a folder for the runs")
    earlier = _earlier_runs(out)
    if earlier and not overwrite:
        raise InputError(
            f"{out.text} already holds recorded runs ({earlier[0].name} ...); choose another "
            "--out or pass --overwrite to replace them"
        )
    for found in earlier:
        found.remove()
    out.fs.makedirs(out.path, exist_ok=True)
    _remove_partials(out)


def _earlier_runs(out: Place) -> list[Place]:
    if not out.is_dir():
        return []
    names = out.names()
    runs = [out.child(n) for n in names if n.startswith("run_") and out.child(n).is_dir()]
    return runs + ([out.child(SUMMARY)] if SUMMARY in names else [])


def _remove_partials(out: Path | Place) -> None:
    out = out if isinstance(out, Place) else place(out)
    for name in out.names() if out.is_dir() else []:
        if fnmatch.fnmatch(name, ".run_*.partial"):
            out.child(name).remove()


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


def print_summary(summary: dict[str, Any], target: str | Path, out: TextIO) -> None:
    """A batch's summary as ``simulate`` and ``demo`` print it: the outcomes, the runs that did
    not end, the work done and where it was recorded."""
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
    summary_file = f"{str(target).rstrip('/')}/{SUMMARY}"
    print(f"recorded in {target} (summary: {summary_file})", file=out)
