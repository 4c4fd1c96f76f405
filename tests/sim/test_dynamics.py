"""Dynamics mode: ground robots with mass stop over a distance that grows with speed, and
collide with each other and with obstacles instead of passing through."""

from __future__ import annotations

import math
from pathlib import Path

import pytest

from robotale.errors import InputError
from robotale.fame_runtime.bus import InProcessBus, Link
from robotale.fame_runtime.clock import SimClock
from robotale.sim.robots import TWIST
from robotale.sim.setup import RobotStart, Setup
from robotale.sim.world import SimWorld
from robotale.sim.worldspec import load_world

MASS, FORCE = 20.0, 40.0  # kg, N: a braking deceleration of 2 m/s2

WORLD = f"""model: none.bpmn
field: [20, 6]
dynamics: {{dynamics}}
physics_rate: 240
bases:
  home: {{{{position: [1, 3]}}}}
robots:
  rover: {{{{kind: ground, base: home, count: 2, max_speed: 2.0, mass: {MASS},
           max_force: {FORCE}, size: [0.6, 0.4, 0.3]}}}}
obstacles:
  wall: {{{{position: [16, 3], size: [0.4, 4, 0.5]}}}}
"""


def start(name: str, x: float, yaw: float, y: float = 3.0) -> RobotStart:
    return RobotStart(name, "rover", x, y, yaw, (x, y), 1.0, 0.0, 0.0)


def world_of(tmp_path: Path, robots: tuple[RobotStart, ...], dynamics: bool = True):
    path = tmp_path / "world.yaml"
    path.write_text(WORLD.format(dynamics=str(dynamics).lower()), encoding="utf-8")
    clock = SimClock(0.0)
    bus = InProcessBus(clock)
    sim = SimWorld(load_world(path), Setup(1, robots, ()), clock=clock, bus=bus)
    sim.start()
    return sim, clock, bus


def command(bus: InProcessBus, robot: str, speed: float) -> None:
    bus.publish(f"/{robot}/cmd_vel", {"linear": {"x": speed}}, msgtype=TWIST)


def braking_distance(tmp_path: Path, speed: float, dynamics: bool = True) -> float:
    robots = (start("rover_1", 1.0, 0.0), start("rover_2", 1.0, 0.0, y=5.0))  # out of the way
    sim, clock, bus = world_of(tmp_path, robots, dynamics)
    try:
        rover = sim.robots["rover_1"]
        command(bus, "rover_1", speed)
        clock.run(until=3.0)
        assert rover.speed == pytest.approx(speed, rel=0.02)
        stopped_at = rover.pose.x
        command(bus, "rover_1", 0.0)
        clock.run(until=6.0)
        assert rover.speed < 1e-3
        return rover.pose.x - stopped_at
    finally:
        sim.close()


def test_a_stop_takes_a_braking_distance_that_grows_with_speed(tmp_path):
    speeds = (0.5, 1.0, 1.5)
    distances = [braking_distance(tmp_path, v) for v in speeds]
    assert distances == sorted(distances) and distances[0] > 0
    for speed, distance in zip(speeds, distances, strict=True):
        # v^2 / 2a with a = force / mass, written out by hand, plus one physics step at most
        assert distance == pytest.approx(speed**2 / (2 * FORCE / MASS), abs=speed / 240 + 0.01)
    # kinematic mode stops at once: no more than the one control step (0.1 s) already moving
    assert braking_distance(tmp_path, 1.5, dynamics=False) <= 1.5 * 0.1 + 1e-9


def test_two_robots_driven_at_each_other_collide_and_the_collision_is_recorded(tmp_path):
    recorded = []
    robots = (start("rover_1", 4.0, 0.0), start("rover_2", 8.0, math.pi))
    sim, clock, bus = world_of(tmp_path, robots)
    bus.tap(lambda e: recorded.append(e) if e.topic.endswith("/collision") else None)
    try:
        command(bus, "rover_1", 1.0)
        command(bus, "rover_2", 1.0)
        clock.run(until=6.0)
        one, two = sim.robots["rover_1"], sim.robots["rover_2"]
        # they stand against each other (0.6 m long each), not through each other
        assert two.pose.x - one.pose.x == pytest.approx(0.6, abs=0.05)
        heard = sorted((e.sender, e.data["data"]) for e in recorded)
        assert heard == [("rover_1", "rover_2"), ("rover_2", "rover_1")]
        first = recorded[0].stamp
        # they met in the middle after (4 - 0.6) / 2 m at about 1 m/s, having started from rest
        assert 1.7 < first < 2.2
        report = sim.report(0.0)["collisions"]
        assert [(c["robot"], c["other"]) for c in report] == [
            ("rover_1", "rover_2"),
            ("rover_2", "rover_1"),
        ]
    finally:
        sim.close()


def test_a_robot_stops_at_an_obstacle_and_the_collision_is_recorded(tmp_path):
    sim, clock, _ = world_of(
        tmp_path, (start("rover_1", 12.0, 0.0), start("rover_2", 2.0, 0.0, y=5.0))
    )
    try:
        command(sim.bus, "rover_1", 1.0)
        clock.run(until=8.0)
        rover = sim.robots["rover_1"]
        # the wall's near face is at 15.8; the rover's centre stays 0.3 m before it
        assert rover.pose.x == pytest.approx(15.5, abs=0.05)
        assert [(c.robot, c.other) for c in sim.contacts.collisions] == [("rover_1", "wall")]
    finally:
        sim.close()


@pytest.mark.parametrize(
    ("change", "message"),
    [
        (("dynamics: true", "dynamics: yes please"), "dynamics is 'yes please'; it must be true"),
        (("physics_rate: 240", "physics_rate: 0"), "physics_rate is 0; it must be positive"),
        (("size: [0.4, 4, 0.5]", "size: [0, 4, 0.5]"), "obstacles.wall.size is [0.0, 4.0, 0.5]"),
        (("max_force: 40.0", "max_force: -1"), "robots.rover.max_force is -1; it must be"),
        (("model:", "network: {loss: 1.5}\nmodel:"), "network.loss is 1.5; it must be at most 1"),
        (("model:", "network: {lose: 0.1}\nmodel:"), "network has unknown key 'lose'"),
        (("model:", "network: {links: {drone: {}}}\nmodel:"), "'sender -> receiver'"),
    ],
)
def test_mistakes_in_the_dynamics_and_network_keys_name_the_key(tmp_path, change, message):
    path = tmp_path / "world.yaml"
    path.write_text(WORLD.format(dynamics="true").replace(*change), encoding="utf-8")
    with pytest.raises(InputError) as error:
        load_world(path)
    assert str(error.value).startswith(f"{path}: ") and message in str(error.value)


def test_the_network_keys_build_a_default_link_and_overrides(tmp_path):
    path = tmp_path / "world.yaml"
    network = 'network: {loss: 0.1, links: {"rover_1 -> rover_2": {latency: 0.3}}}\n'
    path.write_text(network + WORLD.format(dynamics="true"), encoding="utf-8")
    model = load_world(path).network
    assert model.default == Link(loss=0.1)
    assert model.link("rover_1", "rover_2") == Link(latency=0.3, loss=0.1)
    assert model.link("rover_2", "rover_1") == Link(loss=0.1)
