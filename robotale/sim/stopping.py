"""The stop-distance experiment of thesis 5.3.5 on the ``stop`` scenario: the car stopped by
the FAME model and by direct code, ``runs`` runs each at 0.8, 0.9 and 1.0 m/s, and how far
from the wall it halted, beside the thesis' figures.

Run ``i`` of every variant and speed has the same seed (the same sensor noise), so FAME and
direct code see the same readings and differ only by what the engine's work costs.
"""

from __future__ import annotations

import statistics
from collections.abc import Callable, Sequence
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Any, TextIO

from robotale.errors import InputError
from robotale.fame_runtime.manifest import RunManifest, read_manifest
from robotale.sim.run import ENDED, RunPlan
from robotale.sim.worldspec import World

SPEEDS = (0.8, 0.9, 1.0)
VARIANTS = ("fame", "direct")
#: thesis 5.3.5, the text on Figure 5.19: centimetres between the obstacle and the halted
#: robot, averaged over the three speeds (ten runs each), FAME and compiled code; the thesis
#: gives no figure per speed in its text
THESIS_CM = {"simulated": (14.09, 14.67), "physical": (39.07, 40.18)}


@dataclass(frozen=True)
class Cell:
    """One variant at one speed: the distances (m) at which its runs halted from the wall."""

    variant: str
    speed: float
    gaps: tuple[float, ...]
    failed: int = 0  # runs that did not end (time limit, crash)

    @property
    def mean(self) -> float | None:
        return statistics.fmean(self.gaps) if self.gaps else None

    @property
    def sd(self) -> float | None:
        return statistics.stdev(self.gaps) if len(self.gaps) > 1 else None

    @property
    def folder(self) -> str:
        return f"{self.variant}_{self.speed:g}"


def variant_world(world: World, variant: str, speed: float) -> World:
    return replace(world, variables={**world.variables, "variant": variant, "speed": speed})


def gap(world: World, manifest: RunManifest) -> float:
    """Metres between the wall's near face and the car's front once it halted (the car drives
    along x towards the world's first obstacle)."""
    if not world.obstacles or len(world.robots) != 1:
        raise InputError(f"{world.file}: the stop experiment needs one robot and a wall")
    wall, car = world.obstacles[0], world.robots[0]
    (final,) = manifest["robots_final"].values()
    return (wall.position[0] - wall.size[0] / 2) - (final["x"] + car.size[0] / 2)


def run_cells(
    world: World,
    plans_for: Callable[[World], Sequence[RunPlan]],
    simulate: Callable[[Sequence[RunPlan], Path], dict[str, Any]],
    out: Path,
    speeds: Sequence[float] = SPEEDS,
) -> list[Cell]:
    """Simulate every variant at every speed into ``out/<variant>_<speed>/``."""
    cells = []
    for speed in speeds:
        for variant in VARIANTS:
            changed = variant_world(world, variant, speed)
            folder = out / Cell(variant, speed, ()).folder
            summary = simulate(plans_for(changed), folder)
            cells.append(_cell(changed, variant, speed, summary, folder))
    return cells


def _cell(world: World, variant: str, speed: float, summary: dict[str, Any], folder: Path):
    gaps, failed = [], 0
    for case in summary["cases"]:
        if case["status"] != ENDED:
            failed += 1
            continue
        gaps.append(gap(world, read_manifest(folder / case["case"])))
    return Cell(variant, speed, tuple(gaps), failed)


def print_table(cells: Sequence[Cell], out: TextIO) -> None:
    """Speed, FAME and direct code (mean and sd, cm), how much later FAME stopped, and the
    thesis' figures beside the average over the speeds."""
    runs = max((len(c.gaps) + c.failed for c in cells), default=0)
    print(f"stop distance: cm between the wall and the halted car ({runs} runs each)", file=out)
    print(f"{'speed':>9} {'FAME':>16} {'direct code':>16} {'FAME later by':>14}", file=out)
    by = {(c.variant, c.speed): c for c in cells}
    speeds = sorted({c.speed for c in cells})
    for speed in speeds:
        fame, direct = by[("fame", speed)], by[("direct", speed)]
        print(
            f"{speed:>5.1f} m/s {_spread(fame):>16} {_spread(direct):>16} "
            f"{_later(fame.mean, direct.mean):>14}",
            file=out,
        )
    means = [_overall([by[(v, s)] for s in speeds]) for v in VARIANTS]
    print(f"{'all':>9} {_cm(means[0]):>16} {_cm(means[1]):>16} {_later(*means):>14}", file=out)
    print("thesis 5.3.5 (Figure 5.19, averaged over the three speeds):", file=out)
    for where, (fame_cm, direct_cm) in THESIS_CM.items():
        later = f"{direct_cm - fame_cm:.2f} cm"
        print(f"{where:>9} {fame_cm:>16.2f} {direct_cm:>16.2f} {later:>14}", file=out)
    failed = sum(c.failed for c in cells)
    if failed:
        print(f"{failed} runs did not end and are left out", file=out)


def _overall(cells: Sequence[Cell]) -> float | None:
    gaps = [g for c in cells for g in c.gaps]
    return statistics.fmean(gaps) if gaps else None


def _spread(cell: Cell) -> str:
    if cell.mean is None:
        return "-"
    sd = f" ± {cell.sd * 100:.2f}" if cell.sd is not None else ""
    return f"{cell.mean * 100:.2f}{sd}"


def _cm(metres: float | None) -> str:
    return "-" if metres is None else f"{metres * 100:.2f}"


def _later(fame: float | None, direct: float | None) -> str:
    """How much later (closer to the wall) FAME stopped than direct code."""
    return "-" if fame is None or direct is None else f"{(direct - fame) * 100:.2f} cm"
