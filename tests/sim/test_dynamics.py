"""Dynamics mode: ground robots with mass stop over a distance that grows with speed, and
collide with each other and with obstacles instead of passing through (never with weeds);
drones speed up and brake under a limited thrust against drag."""

from __future__ import annotations

import math
from pathlib import Path

import pytest

from robotale.errors import InputError
from robotale.fame_runtime.bus import InProcessBus, Link
from robotale.fame_runtime.clock import SimClock
from robotale.sim.robots import EMPTY, TWIST
from robotale.sim.setup import Placed, RobotStart, Setup
from robotale.sim.world import SimWorld
from robotale.sim.worldspec import load_world

MASS, FORCE = 20.0, 40.0  # kg, N: a braking deceleration of 2 m/s2
DRONE_MASS, THRUST = 0.5, 1.5  # kg, N: 3 m/s2 without drag

WORLD = f"""model: none.bpmn
field: [20, 6]
dynamics: {{dynamics}}
physics_rate: 240
bases:
  home: {{{{position: [1, 3]}}}}
robots:
  rover: {{{{kind: ground, base: home, count: 2, max_speed: 2.0, mass: {MASS},
           max_force: {FORCE}, size: [0.6, 0.4, 0.3]}}}}
  copter: {{{{kind: drone, base: home, max_speed: 3.0, mass: {DRONE_MASS}, max_force: {THRUST},
            drag: {{drag}}, size: [0.4, 0.4, 0.1]}}}}
obstacles:
  wall: {{{{position: [16, 3], size: [0.4, 4, 0.5]}}}}
weeds: {{{{count: 0}}}}
"""


def start(name: str, x: float, yaw: float, y: float = 3.0) -> RobotStart:
    return RobotStart(name, "rover", x, y, yaw, (x, y), 1.0, 0.0, 0.0)


def world_of(
    tmp_path: Path,
    robots: tuple[RobotStart, ...],
    dynamics: bool = True,
    drag: float = 0.0,
    objects: tuple[Placed, ...] = (),
):
    path = tmp_path / "world.yaml"
    path.write_text(WORLD.format(dynamics=str(dynamics).lower(), drag=drag), encoding="utf-8")
    clock = SimClock(0.0)
    bus = InProcessBus(clock)
    sim = SimWorld(load_world(path), Setup(1, robots, objects), clock=clock, bus=bus)
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


def flight_braking_distance(tmp_path: Path, speed: float, drag: float = 0.0) -> float:
    """How far the drone flies on from ``speed`` once told to hover (it flies along +x)."""
    copter = RobotStart("copter", "copter", 1.0, 3.0, 0.0, (1.0, 3.0), 1.0, 0.0, 0.0)
    sim, clock, bus = world_of(tmp_path, (copter,), drag=drag)
    try:
        drone = sim.robots["copter"]
        bus.publish("/copter/takeoff", {}, msgtype=EMPTY)
        clock.run(until=3.0)  # 1.5 m up at 0.75 m/s
        command(bus, "copter", speed)
        clock.run(until=6.0)
        assert drone.speed == pytest.approx(speed, rel=0.05)
        stopped_at = drone.pose.x
        command(bus, "copter", 0.0)
        clock.run(until=9.0)
        assert drone.speed < 1e-3
        return drone.pose.x - stopped_at
    finally:
        sim.close()


def test_a_drone_accelerates_and_brakes_under_its_thrust_limit(tmp_path):
    copter = RobotStart("copter", "copter", 1.0, 3.0, 0.0, (1.0, 3.0), 1.0, 0.0, 0.0)
    sim, clock, bus = world_of(tmp_path, (copter,))
    try:
        drone = sim.robots["copter"]
        bus.publish("/copter/takeoff", {}, msgtype=EMPTY)
        clock.run(until=3.0)
        command(bus, "copter", 3.0)
        clock.run(until=3.5)
        # half a second at THRUST / DRONE_MASS = 3 m/s2: 1.5 m/s, not the 3 m/s commanded
        assert drone.speed == pytest.approx(1.5, abs=0.31)
    finally:
        sim.close()


def test_a_drone_brakes_over_a_distance_that_grows_with_speed(tmp_path):
    speeds = (0.5, 1.0, 2.0)
    distances = [flight_braking_distance(tmp_path, v) for v in speeds]
    for speed, distance in zip(speeds, distances, strict=True):
        # v^2 / 2a with a = thrust / mass, by hand, give or take one control step (0.1 s)
        assert distance == pytest.approx(speed**2 / (2 * THRUST / DRONE_MASS), abs=speed * 0.1)
    assert distances == sorted(distances) and distances[0] > 0
    # drag helps the rotors brake: a shorter distance from the same speed
    assert flight_braking_distance(tmp_path, 2.0, drag=0.2) < distances[-1] - 0.05


def test_a_robot_drives_over_a_weed(tmp_path):
    weed = Placed("weed", "weed_1", 3.0, 3.0)
    sim, clock, bus = world_of(
        tmp_path, (start("rover_1", 1.0, 0.0), start("rover_2", 1.0, 0.0, y=5.0)), objects=(weed,)
    )
    try:
        command(bus, "rover_1", 0.5)
        clock.run(until=8.0)
        # 7.5 s at 0.5 m/s after speeding up for a quarter second: past the weed at x = 3
        assert sim.robots["rover_1"].pose.x == pytest.approx(1.0 + 0.5 * 7.875, abs=0.1)
        assert sim.contacts.collisions == []
    finally:
        sim.close()


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
        (("count: 2,", "count: 2, busy_ignores: [3],"), "robots.rover.busy_ignores holds 3;"),
        (("count: 2,", "count: 2, busy_ignores: job,"), "robots.rover.busy_ignores must be a list"),
        (("model:", "network: {loss: 1.5}\nmodel:"), "network.loss is 1.5; it must be at most 1"),
        (("model:", "network: {lose: 0.1}\nmodel:"), "network has unknown key 'lose'"),
        (("model:", "network: {links: {drone: {}}}\nmodel:"), "'sender -> receiver'"),
    ],
)
def test_mistakes_in_the_dynamics_and_network_keys_name_the_key(tmp_path, change, message):
    path = tmp_path / "world.yaml"
    path.write_text(WORLD.format(dynamics="true", drag=0.0).replace(*change), encoding="utf-8")
    with pytest.raises(InputError) as error:
        load_world(path)
    assert str(error.value).startswith(f"{path}: ") and message in str(error.value)


def test_the_network_keys_build_a_default_link_and_overrides(tmp_path):
    path = tmp_path / "world.yaml"
    network = 'network: {loss: 0.1, links: {"rover_1 -> rover_2": {latency: 0.3}}}\n'
    path.write_text(network + WORLD.format(dynamics="true", drag=0.0), encoding="utf-8")
    model = load_world(path).network
    assert model.default == Link(loss=0.1)
    assert model.link("rover_1", "rover_2") == Link(latency=0.3, loss=0.1)
    assert model.link("rover_2", "rover_1") == Link(loss=0.1)
