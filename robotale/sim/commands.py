"""What ``robotale simulate`` does; :mod:`robotale.cli` only parses the arguments."""

from __future__ import annotations

import os
import sys
from collections.abc import Sequence
from dataclasses import replace
from pathlib import Path
from typing import Any, TextIO

from robotale.errors import InputError, ModelError
from robotale.fame_runtime.bus import InProcessBus
from robotale.fame_runtime.clock import SimClock
from robotale.fame_runtime.mission import Mission
from robotale.fame_runtime.parser import parse
from robotale.sim import messages, scenarios
from robotale.sim.batch import simulate_batch
from robotale.sim.faults import Fault, parse_fault
from robotale.sim.run import RunPlan, model_topics, skills_of
from robotale.sim.setup import draw
from robotale.sim.worldspec import World, load_world


def resolve_world(
    scenario: str | None, model: Path | None = None, world: Path | None = None
) -> tuple[World, str]:
    """The world to simulate and the scenario's name: a shipped scenario, or a world file;
    ``model`` replaces the world's mission model."""
    if world is not None:
        loaded = load_world(world, model)
        return loaded, scenario or Path(world).stem
    if scenario is None:
        raise InputError(
            f"name a scenario ({', '.join(scenarios.names())}) or give --world (with --model)"
        )
    path = scenarios.world_file(scenario)
    if path is None:
        raise InputError(
            f"there is no scenario {scenario!r}; the scenarios are {', '.join(scenarios.names())} "
            "(or give --world and --model)"
        )
    return load_world(path, model), scenario


def adjust(
    world: World,
    *,
    counts: dict[str, int] | None = None,
    weeds: tuple[int, int] | None = None,
    time_limit: float | None = None,
    rate: float | None = None,
) -> World:
    """The world with the command line's overrides."""
    world = world.with_counts(counts or {})
    if weeds is not None:
        if not any(o.kind == "weed" for o in world.objects):
            raise InputError(f"{world.file}: this world has no weeds to count")
        objects = tuple(replace(o, count=weeds) if o.kind == "weed" else o for o in world.objects)
        world = replace(world, objects=objects)
    if time_limit is not None:
        world = replace(world, time_limit=time_limit)
    if rate is not None:
        world = replace(world, record_rate=rate)
    return world


def check(world: World) -> None:
    """Refuse, before any run starts, what would make every run fail: a model the engine
    cannot run or that the robots do not fit, message types unknown to ROS 2, a world with no
    room for its objects."""
    if not world.model.is_file():
        raise InputError(f"{world.file}: the mission model {world.model} does not exist")
    definitions = parse(world.model)
    clock = SimClock()
    Mission(
        definitions,
        robots=world.robot_names(),
        clock=clock,
        bus=InProcessBus(clock),
        skills=skills_of(world),
        library=world.library,
    )
    signals, _ = model_topics(definitions)
    for topic, msgtype in signals.items():
        if not messages.known(msgtype):
            raise ModelError(
                f"{world.model}: the signal {topic} has the message type {msgtype}, which is "
                "not a ROS 2 Humble type the recorder can write"
            )
    draw(world, 0)


def plans(
    world: World,
    scenario: str,
    *,
    runs: int,
    seed: int,
    first: int = 1,
    faults: Sequence[str] = (),
    storage: str = "sqlite3",
    extra_topics: Sequence[str] = (),
    settings: dict[str, Any] | None = None,
) -> list[RunPlan]:
    if runs < 1 or first < 1:
        raise InputError("--runs and --first must be at least 1")
    parsed: tuple[Fault, ...] = tuple(
        parse_fault(text, world.robot_names()) for text in (*world.faults, *faults)
    )
    return [
        RunPlan(
            world,
            index,
            seed,
            scenario,
            parsed,
            storage,
            tuple(extra_topics),
            dict(settings or {}),
        )
        for index in range(first, first + runs)
    ]


def simulate_command(args: Any, out: TextIO | None = None) -> int:
    """``robotale simulate``: a batch (or one run in pybullet's window with --gui)."""
    out = out or sys.stdout
    world, scenario = resolve_world(args.scenario, args.model, args.world)
    counts = dict(_count(text) for text in args.count)
    if args.tractors is not None:
        counts["tractor"] = args.tractors
    world = adjust(
        world,
        counts=counts,
        weeds=_weeds(args.weeds) if args.weeds else None,
        time_limit=args.time_limit,
        rate=args.rate,
    )
    check(world)
    batch = plans(
        world,
        scenario,
        runs=args.runs,
        seed=args.seed,
        first=args.first,
        faults=args.fault,
        storage=args.storage,
        extra_topics=_topics(args.topics),
        settings=_overrides(args),
    )
    target = Path(args.out) if args.out else Path("runs") / scenario
    if args.gui and not (os.environ.get("DISPLAY") or os.environ.get("WAYLAND_DISPLAY")):
        raise InputError("--gui needs a display (DISPLAY is not set); run without --gui")
    watching = args.gui or bool(args.pace)
    summary = simulate_batch(
        batch,
        target,
        workers=args.workers,
        overwrite=args.overwrite,
        progress=not (args.quiet or watching),
        gui=args.gui,
        pace=(args.pace or 1.0) if watching else None,
    )
    print_summary(summary, target, out)
    return 0


def print_summary(summary: dict[str, Any], target: Path, out: TextIO) -> None:
    outcomes = ", ".join(f"{n} {status}" for status, n in sorted(summary["outcomes"].items()))
    runs, workers = summary["runs"], summary["workers"]
    where = f"{workers} worker{'s' if workers != 1 else ''}" if workers else "in this process"
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


def _overrides(args: Any) -> dict[str, Any]:
    """The command line's changes to the world, for the manifests."""
    given = {
        "counts": dict(_count(text) for text in args.count) or None,
        "tractors": args.tractors,
        "weeds": args.weeds,
        "faults": list(args.fault) or None,
        "extra_topics": _topics(args.topics) or None,
    }
    return {key: value for key, value in given.items() if value is not None}


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
