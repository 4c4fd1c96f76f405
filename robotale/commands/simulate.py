"""``robotale simulate``: a batch of simulated runs (or one run in pybullet's window)."""

from __future__ import annotations

import contextlib
import errno
import os
import shutil
import sqlite3
import sys
from collections.abc import Callable, Iterator, Sequence
from dataclasses import replace
from pathlib import Path
from typing import Any, TextIO

from robotale.ekg.build import check_log_name
from robotale.ekg.connection import session_driver
from robotale.errors import InputError
from robotale.extras import require
from robotale.fame_runtime.bus import Bus, InProcessBus
from robotale.fame_runtime.clock import EngineCost, WallClock
from robotale.results.monitor import alert_limits
from robotale.results.watched_run import WatchedRun
from robotale.sim import stopping
from robotale.sim.batch import print_summary, simulate_batch
from robotale.sim.plans import adjust, check, plans, resolve_world
from robotale.sim.run import CRASHED, RunPlan, Watch
from robotale.sim.worldspec import World
from robotale.storage import local_path
from robotale.thresholds import LOW_BATTERY_PERCENT
from robotale.webapp.live_address import dashboard_url, live_page, serves_live


def simulate_command(
    scenario: str | None = None,
    *,
    model: Path | None = None,
    world: Path | None = None,
    library: Path | None = None,
    thesis: bool = False,
    runs: int | None = None,
    seed: int = 1,
    first: int = 1,
    out_dir: str | Path | None = None,
    tractors: int | None = None,
    counts: Sequence[str] = (),
    weeds: str | None = None,
    faults: Sequence[str] = (),
    storage: str = "sqlite3",
    distro: str = "humble",
    rate: float | None = None,
    topics: str | None = None,
    time_limit: float | None = None,
    engine_cost: str | None = None,
    workers: int | None = None,
    executor: str | None = None,
    gui: bool = False,
    pace: float | None = None,
    overwrite: bool = False,
    quiet: bool = False,
    live: bool = False,
    log: str | None = None,
    silence: float = 10.0,
    battery: float = LOW_BATTERY_PERCENT,
    message_timeout: list[str] | None = None,
    durations_from: list[str] | None = None,
    dashboard: str | None = None,
    out: TextIO | None = None,
    err: TextIO | None = None,
) -> int:
    """A batch of ``runs`` runs recorded under ``out_dir`` (``runs/<scenario>``; a folder or an
    fsspec URL); with ``gui``
    one run in pybullet's window at ``pace`` simulated seconds per wall second. ``executor``
    (``local[:N]``, ``dask://HOST:PORT``) says where the runs go; ``thesis`` takes the
    scenario's world calibrated to the thesis. The ``stop`` scenario runs the stop-distance
    experiment (``runs`` per variant and speed, 10) and prints its table. With ``live`` the
    monitor watches each run as it goes (at ``pace``, default 1: as fast as the wall clock):
    its tags are printed and stored as the live log ``log`` (a batch: ``log_run_0001`` ...;
    default the scenario's name and the run's), and alerts raised as ``robotale monitor``
    raises them (``silence``, ``battery``, ``message_timeout``, ``durations_from``); the live
    run's Mission page is on the dashboard at ``dashboard``."""
    out, err = out or sys.stdout, err or sys.stderr
    if runs is not None and runs < 1:
        raise InputError(f"--runs {runs}: give the number of runs to simulate, 1 or more.")
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
    if engine_cost is not None:
        loaded = replace(loaded, engine_cost=_engine_cost(engine_cost))
    experiment = scenario == "stop" and world is None
    runs = runs if runs is not None else (10 if experiment else 1)
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

    def plans_for(changed: World) -> list[RunPlan]:
        return plans(
            changed,
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
    if not live and (log or dashboard or message_timeout or durations_from):
        raise InputError(
            "--log, --dashboard, --message-timeout and --durations-from go with --live"
        )
    if live and experiment:
        raise InputError("--live watches a mission's runs; the stop experiment is no mission run")
    if live:  # a person watches the live run as it goes, as in pybullet's window
        pace = pace or 1.0
    if gui and not (os.environ.get("DISPLAY") or os.environ.get("WAYLAND_DISPLAY")):
        raise InputError("--gui needs a display (DISPLAY is not set); run without --gui")
    watching = gui or bool(pace)
    watch: Watch | None = None  # the monitor, with --live

    def simulate(batch: list[RunPlan], folder: Path) -> dict[str, Any]:
        return simulate_batch(
            batch,
            folder,
            workers=workers,
            executor=executor,
            overwrite=overwrite,
            progress=not (quiet or watching),
            gui=gui,
            pace=(pace or 1.0) if watching else None,
            watch=watch,
        )

    if experiment:
        if (folder := local_path(target)) is None:
            raise InputError(
                f"--out {target}: the stop experiment reads its runs back to measure them; "
                "give it a folder on this machine"
            )
        return stop_experiment(loaded, plans_for, simulate, folder, out)
    batch = plans_for(loaded)
    if not live:
        return _simulated(simulate, batch, target, out)
    url = dashboard_url(dashboard)
    with session_driver() as driver, _alert_relay() as relay:
        limits = alert_limits(driver, silence, battery, message_timeout, durations_from)

        def name_of(case: str) -> str:
            return log if log and len(batch) == 1 else f"{log or scenario}_{case}"

        check_log_name(name_of(batch[0].case))  # before any run, not as a crashed one

        def watched(case: str, robots: list[str], bus: InProcessBus) -> Callable[[], None]:
            name = name_of(case)
            print(f"# monitoring {', '.join(robots)} as {name}", file=err, flush=True)
            run = WatchedRun(
                driver, name, loaded.model, robots, bus, limits, out, _announce(url, err), relay
            )
            return lambda: print(f"# {name}: {run.end()} tags stored", file=err, flush=True)

        watch = watched
        return _simulated(simulate, batch, target, out)


def _simulated(simulate, batch: list[RunPlan], target: str | Path, out: TextIO) -> int:
    """Simulate ``batch`` into ``target``, print its summary; the exit status."""
    try:
        summary = simulate(batch, target)
    except (OSError, sqlite3.OperationalError) as error:
        if (folder := local_path(target)) is None or not _disk_full(error):
            raise
        raise InputError(_no_space(folder, batch)) from None
    print_summary(summary, target, out)
    return _crash_status(summary)


@contextlib.contextmanager
def _alert_relay() -> Iterator[Bus | None]:
    """A bus on the DDS domain (``ROS_DOMAIN_ID``) the live runs' alerts are published on too,
    for robots and operators there, when Cyclone DDS is installed; else None."""
    try:
        require("dds")
    except InputError:
        yield None
        return
    # Cyclone DDS is an optional extra (robotale[dds]) and 0.9 s to import: --live only
    from robotale.fame_runtime.dds import DdsBus

    relay = DdsBus(WallClock(), node="monitor")
    try:
        yield relay
    finally:
        relay.close()


def _announce(url: str, err: TextIO) -> Callable[[str], None]:
    """Says where the live run ``name`` is followed, once its first tag is stored."""

    def announce(name: str) -> None:
        page = live_page(url, name)
        if serves_live(url, name):
            print(f"# Mission page: {page}", file=err, flush=True)
        else:
            print(
                f"# no dashboard answers at {url}: start `robotale serve` (same Neo4j) and "
                f"open {page}",
                file=err,
                flush=True,
            )

    return announce


def _disk_full(error: Exception) -> bool:
    if isinstance(error, OSError):
        return error.errno in (errno.ENOSPC, errno.EDQUOT)
    return "disk is full" in str(error)  # sqlite3, writing a bag


def _no_space(folder: Path, batch: list[RunPlan]) -> str:
    """The sentence for a batch the disk of ``folder`` could not hold (the runs recorded
    before stay whole; the one that stopped was removed with its hidden folder)."""
    done = [run for plan in batch if (run := folder / plan.case).is_dir()]
    size = sum(f.stat().st_size for run in done for f in run.rglob("*") if f.is_file())
    free = shutil.disk_usage(folder).free
    if not done:
        return (
            f"The disk of {folder} is full: not one run of {len(batch)} fitted in its "
            f"{free / 2**20:.1f} MB free; nothing was kept."
        )
    each = size / len(done)
    return (
        f"The disk of {folder} is full: {len(batch)} runs need about "
        f"{each * len(batch) / 2**20:.1f} MB there ({each / 2**20:.1f} MB each), and only "
        f"{len(done)} fitted; they are kept whole, the run that did not fit was removed."
    )


def _crash_status(summary: dict[str, Any]) -> int:
    """1 when any run crashed, said on stderr with each one's reason; 0 otherwise."""
    crashed = [case for case in summary["cases"] if case["status"] == CRASHED]
    if not crashed:
        return 0
    which = "; ".join(
        f"{case['case']}: {case['reason'] or 'no reason recorded'}" for case in crashed
    )
    print(
        f"robotale: {len(crashed)} of {summary['runs']} run(s) crashed ({which}).",
        file=sys.stderr,
    )
    return 1


def stop_experiment(world: World, plans_for, simulate, target: Path, out: TextIO) -> int:
    """The stop scenario: both variants at each speed, one batch folder each, then the table."""
    cells = stopping.run_cells(world, plans_for, simulate, target)
    for cell in cells:
        ended = len(cell.gaps)
        print(
            f"{cell.variant} at {cell.speed:g} m/s: {ended} runs ended in {target / cell.folder}",
            file=out,
        )
    print_table_of(world, cells, out)
    return 0 if all(cell.gaps for cell in cells) else 1


def print_table_of(world: World, cells, out: TextIO) -> None:
    cost = world.engine_cost
    what = ", ".join(f"{k} {v:g} s" for k, v in cost.as_dict().items()) if cost else "none"
    print(f"engine cost: {what}", file=out)
    stopping.print_table(cells, out)


def _engine_cost(text: str) -> EngineCost:
    """``--engine-cost script=0.002,condition=0.0005,step=0.0001``, ``measured=F`` or 0."""
    if text.strip() in ("0", "none"):
        return EngineCost()
    fields = set(EngineCost.__dataclass_fields__)
    costs = {}
    for part in text.split(","):
        key, sep, value = part.partition("=")
        key = key.strip()
        try:
            number = float(value)
        except ValueError:
            number = -1.0
        if not sep or key not in fields or number < 0:
            raise InputError(
                f"--engine-cost {text!r}: {part.strip()!r} must be KEY=SECONDS with KEY one of "
                f"{', '.join(sorted(fields))} (or 0 for none)"
            )
        costs[key] = number
    if costs.get("measured") and len(costs) > 1:
        raise InputError(f"--engine-cost {text!r}: either measured=FACTOR or fixed costs")
    return EngineCost(**costs)


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
