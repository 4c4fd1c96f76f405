"""A batch of simulated runs, planned: the world a scenario or a world file names, the
command line's overrides applied, checked before any run starts, and one :class:`RunPlan` per
run."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import replace
from pathlib import Path
from typing import Any

from robotale.errors import InputError, ModelError
from robotale.fame_runtime.bus import InProcessBus
from robotale.fame_runtime.clock import SimClock
from robotale.fame_runtime.library import Library
from robotale.fame_runtime.mission import Mission
from robotale.fame_runtime.parser import parse
from robotale.sim import messages, scenarios
from robotale.sim.faults import Fault, parse_fault
from robotale.sim.provides import lacks
from robotale.sim.run import RunPlan, model_topics, skills_of
from robotale.sim.setup import draw
from robotale.sim.worldspec import World, load_world


def resolve_world(
    scenario: str | None,
    model: Path | None = None,
    world: Path | None = None,
    library: Path | None = None,
    *,
    preset: str | None = None,
) -> tuple[World, str]:
    """The world to simulate and the scenario's name: a shipped scenario (its ``preset``
    world, such as ``thesis``, when named), or a world file; ``model`` replaces the world's
    mission model, ``library`` its building blocks."""
    loaded, name = _world(scenario, model, world, preset)
    if library is not None:
        if not Path(library).is_dir():
            raise InputError(f"--library {library}: there is no such folder")
        loaded = replace(loaded, library=Path(library))
    return loaded, name


def _world(
    scenario: str | None, model: Path | None, world: Path | None, preset: str | None
) -> tuple[World, str]:
    if preset is not None and (world is not None or scenario is None):
        raise InputError(f"--{preset} takes a shipped scenario's {preset} world, not --world")
    if world is not None:
        loaded = load_world(world, model)
        return loaded, scenario or Path(world).stem
    if scenario is None:
        raise InputError(
            f"name a scenario ({', '.join(scenarios.names())}) or give --world (with --model)"
        )
    if preset is not None and scenario in scenarios.names():
        path = scenarios.world_file(scenario, preset)
        if path is None:
            having = ", ".join(scenarios.presets(preset)) or "none"
            raise InputError(
                f"the scenario {scenario} has no {preset} world (scenarios with one: {having})"
            )
        return load_world(path, model), scenario
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


def check(world: World) -> list[str]:
    """Refuse, before any run starts, what would make every run fail: a model the engine
    cannot run or that the robots do not fit, message types unknown to ROS 2, a world with no
    room for its objects. Returns what the model needs that the robots do not provide (runs
    go on without it: a script waits for a topic nobody publishes)."""
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
    library = Library(world.library) if world.library else None
    return lacks(definitions, world, library)


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
    distro: str = "humble",
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
            distro,
        )
        for index in range(first, first + runs)
    ]
