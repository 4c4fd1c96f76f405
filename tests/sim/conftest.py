"""Fixtures of the simulation tests: real pybullet worlds with real engines (helpers that
record and read bags are in ``simbags``)."""

from __future__ import annotations

import pytest
from simbags import full_batteries

from robotale.sim import scenarios
from robotale.sim.plans import adjust
from robotale.sim.worldspec import World, load_world


@pytest.fixture
def short_agri() -> World:
    """1 drone, 2 tractors, 2 weeds, full batteries."""
    world = load_world(scenarios.world_file("agri"))
    return full_batteries(adjust(world, counts={"tractor": 2}, weeds=(2, 2)))


@pytest.fixture
def rexdingo() -> World:
    return full_batteries(load_world(scenarios.world_file("rexdingo")))
