"""Generated missions simulated once per session, with their truth and their prepared logs."""

from __future__ import annotations

from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path

import pandas as pd
import pytest
from compare import prepared

from robotale.sim.batch import simulate_batch
from robotale.sim.generate import Mission, generate
from robotale.sim.run import RunPlan
from robotale.sim.worldspec import load_world

#: the seeds ``make test`` checks (each a mission and world of its own, one run each); the
#: verify-findings target runs many more
SEEDS = tuple(range(1, 9))


@dataclass(frozen=True)
class Simulated:
    seed: int
    mission: Mission
    batch: Path
    log: pd.DataFrame


def simulate_generated(seed: int, folder: Path, runs: int = 1) -> Simulated:
    """Generate the mission of ``seed``, simulate ``runs`` runs of it and prepare their log."""
    mission = generate(seed, folder)
    world = load_world(mission.world)
    plans = [RunPlan(world, index, seed) for index in range(1, runs + 1)]
    batch = folder / "runs"
    simulate_batch(plans, batch, workers=0, overwrite=True)
    return Simulated(seed, mission, batch, prepared(batch))


@pytest.fixture(scope="session")
def generated(tmp_path_factory: pytest.TempPathFactory) -> Iterator[list[Simulated]]:
    root = tmp_path_factory.mktemp("generated")
    yield [simulate_generated(seed, root / f"seed_{seed}") for seed in SEEDS]
