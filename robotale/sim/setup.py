"""What varies from one run to the next, drawn from the run's seed: where the weeds (or
targets) are, where each robot starts, how charged its battery is and how fast it drains.

The same seed always gives the same setup; the manifest of a run records it.
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass, replace

import numpy as np

from robotale.errors import InputError
from robotale.sim.worldspec import ObjectsSpec, Range, RobotSpec, World

MIN_GAP = 0.6  # metres between two objects, so each is found and cut on its own


@dataclass(frozen=True)
class RobotStart:
    name: str
    group: str
    x: float
    y: float
    yaw: float
    home: tuple[float, float]  # its charging spot
    level: float
    drain: float
    move_drain: float
    phase: float = 0.0  # share of a control step its sensors and motors lag the clock's ticks
    flight_drain: float = 0.0


@dataclass(frozen=True)
class Placed:
    kind: str  # weed | target
    id: str  # weed_1 ...
    x: float
    y: float


@dataclass(frozen=True)
class Setup:
    seed: int
    robots: tuple[RobotStart, ...]
    objects: tuple[Placed, ...]

    def start_of(self, name: str) -> RobotStart:
        return next(r for r in self.robots if r.name == name)

    def as_dict(self) -> dict:
        return {
            "robots": {r.name: _rounded(asdict(r)) for r in self.robots},
            "objects": [_rounded(asdict(o)) for o in self.objects],
        }


def run_seed(batch_seed: int, index: int) -> int:
    """The seed of run ``index`` (1-based) of a batch: independent of the batch's size, so
    run 5 of a 70-run batch is run 5 of a 5-run batch with the same seed."""
    return int(np.random.SeedSequence([batch_seed, index]).generate_state(1)[0])


def draw(world: World, seed: int) -> Setup:
    rng = np.random.default_rng(seed)
    robots = [start for spec in world.robots for start in _robot_starts(world, spec, rng)]
    # Robots' control loops are not synchronised: each runs at its own phase, evenly spread
    # and shuffled per run, so two robots never sense and answer at the very same instant.
    order = rng.permutation(len(robots))
    robots = tuple(
        replace(start, phase=float(rank) / len(robots))
        for start, rank in zip(robots, order, strict=True)
    )
    objects: list[Placed] = []
    for spec in world.objects:
        objects += _place(world, spec, rng, objects)
    return Setup(seed, robots, tuple(objects))


def _robot_starts(world: World, spec: RobotSpec, rng: np.random.Generator):
    base = world.bases[spec.base]
    for index, name in enumerate(spec.names()):
        home = (
            base.position[0] + index * spec.spacing[0],
            base.position[1] + index * spec.spacing[1],
        )
        angle, distance = (
            rng.uniform(-math.pi, math.pi),
            spec.start_jitter * math.sqrt(rng.uniform()),
        )
        battery = spec.battery
        yield RobotStart(
            name=name,
            group=spec.name,
            x=home[0] + distance * math.cos(angle),
            y=home[1] + distance * math.sin(angle),
            yaw=rng.uniform(-math.pi, math.pi) if spec.start_jitter else 0.0,
            home=home,
            level=_uniform(rng, battery.level),
            drain=_uniform(rng, battery.drain),
            move_drain=_uniform(rng, battery.move_drain),
            # drawn after the others, so worlds without it draw what they always drew
            flight_drain=_uniform(rng, battery.flight_drain),
        )


def _place(
    world: World, spec: ObjectsSpec, rng: np.random.Generator, taken: list[Placed]
) -> list[Placed]:
    count = int(rng.integers(spec.count[0], spec.count[1] + 1))
    (x_low, x_high), (y_low, y_high) = spec.area or (
        (spec.margin, world.field[0] - spec.margin),
        (spec.margin, world.field[1] - spec.margin),
    )
    placed: list[Placed] = []
    for n in range(1, count + 1):
        for _ in range(1000):
            x, y = rng.uniform(x_low, x_high), rng.uniform(y_low, y_high)
            if _free(world, x, y, [*taken, *placed]):
                placed.append(Placed(spec.kind, f"{spec.kind}_{n}", x, y))
                break
        else:
            raise InputError(
                f"{world.file}: there is no room for {count} {spec.kind}s {MIN_GAP} m apart "
                "away from the bases; make the area larger or the count smaller"
            )
    return placed


def _free(world: World, x: float, y: float, others: list[Placed]) -> bool:
    if any(math.hypot(x - o.x, y - o.y) < MIN_GAP for o in others):
        return False
    return all(
        math.hypot(x - b.position[0], y - b.position[1]) > b.radius + 0.3
        for b in world.bases.values()
    )


def _uniform(rng: np.random.Generator, bounds: Range) -> float:
    low, high = bounds
    return float(rng.uniform(low, high)) if high > low else float(low)


def _rounded(values: dict) -> dict:
    return {k: round(v, 4) if isinstance(v, float) else v for k, v in values.items()}
