"""Ground robots as bodies with mass: driven by motor forces, limited by grip, colliding.

In dynamics mode (``dynamics: true`` in the world file) a ground robot's body has its ``mass``
and every physics step (``physics_rate`` a second) its drive pushes it towards the commanded
forward speed and turn rate, as a velocity controller on the wheels would:

- the forward force is what would reach the commanded speed in one step, limited to the
  motors' ``max_force`` (N), so speeding up and stopping take time: a robot told to stop at
  speed v travels about ``v**2 / (2 * max_force / mass)`` before it stands;
- the sideways force cancels sliding, and forward and sideways together never exceed the tyres'
  grip, ``friction * mass * g``;
- the yaw torque does the same for the turn rate, limited to ``max_torque`` (N m), against the
  box's moment of inertia.

Pybullet integrates the rest (inertia, contacts): robots stop against each other and against
obstacles instead of driving through them. Each contact that begins between a robot and another
robot or an obstacle is a :class:`Collision`; the world publishes it on
``/<robot>/collision`` (``std_msgs/msg/String``, the other body's name) for both robots of a
pair.

A drone (no wheels, above everything) is not a pybullet body with mass; :func:`fly` integrates
its horizontal motion each control step in :data:`FLIGHT_SUBSTEPS` steps: its rotors' thrust
pushes it towards the commanded velocity with at most ``max_force`` N, and air drag of
``drag * v**2`` N holds it back, on its ``mass``. So it speeds up and brakes instead of
jumping to the commanded speed; told to stop at speed v it still travels about
``v**2 / (2 * max_force / mass)`` (less with drag).
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass

from robotale.sim.physics import GRAVITY, Physics
from robotale.sim.robots import SimRobot

COLLISION = "std_msgs/msg/String"
FLIGHT_SUBSTEPS = 5  # integration steps of a drone's flight per control step


@dataclass(frozen=True)
class Collision:
    time: float
    robot: str
    other: str  # a robot's name or an obstacle's


def drive(physics: Physics, robot: SimRobot, dt: float) -> None:
    """Push ``robot``'s body for one physics step of ``dt`` seconds towards its command."""
    spec = robot.spec
    _, yaw, velocity, yaw_rate = physics.motion(robot.body)
    forward, turn = robot.wanted()
    heading, side = (math.cos(yaw), math.sin(yaw)), (-math.sin(yaw), math.cos(yaw))
    along = velocity[0] * heading[0] + velocity[1] * heading[1]
    across = velocity[0] * side[0] + velocity[1] * side[1]
    push = _clip(spec.mass * (forward - along) / dt, spec.max_force)
    hold = -spec.mass * across / dt
    grip = spec.friction * spec.mass * GRAVITY
    total = math.hypot(push, hold)
    if total > grip:  # the tyres slip: the force they pass on is capped by friction
        push, hold = push * grip / total, hold * grip / total
    force = (
        push * heading[0] + hold * side[0],
        push * heading[1] + hold * side[1],
        0.0,
    )
    length, width, _ = spec.size
    inertia = spec.mass * (length**2 + width**2) / 12
    torque = _clip(inertia * (turn - yaw_rate) / dt, spec.max_torque)
    physics.push(robot.body, force, torque)


def fly(robot: SimRobot, dt: float) -> None:
    """Move a flying robot ``dt`` seconds under thrust and drag towards its command."""
    if dt <= 0:
        return
    spec = robot.spec
    forward, _ = robot.wanted()
    yaw = robot.pose.yaw
    wanted = (forward * math.cos(yaw), forward * math.sin(yaw))
    h = dt / FLIGHT_SUBSTEPS
    vx, vy = robot.velocity
    for _ in range(FLIGHT_SUBSTEPS):
        thrust = _limited(
            (spec.mass * (wanted[0] - vx) / h, spec.mass * (wanted[1] - vy) / h), spec.max_force
        )
        speed = math.hypot(vx, vy)
        vx += (thrust[0] - spec.drag * speed * vx) / spec.mass * h
        vy += (thrust[1] - spec.drag * speed * vy) / spec.mass * h
        robot.pose.x += vx * h
        robot.pose.y += vy * h
    robot.velocity = (vx, vy)
    robot.speed = math.hypot(vx, vy)


def _limited(force: tuple[float, float], limit: float) -> tuple[float, float]:
    size = math.hypot(*force)
    return force if size <= limit else (force[0] * limit / size, force[1] * limit / size)


def follow(physics: Physics, robot: SimRobot) -> None:
    """Take the robot's pose and speed from its body after a step."""
    position, yaw, velocity, _ = physics.motion(robot.body)
    robot.pose.x, robot.pose.y, robot.pose.yaw = position[0], position[1], yaw
    robot.speed = math.hypot(velocity[0], velocity[1])


class Contacts:
    """Which robot touches which body, to report each contact once, when it begins."""

    def __init__(self, names: Mapping[int, str]) -> None:
        self.names = names  # body -> name, for robots and obstacles (others are ignored)
        self._touching: set[tuple[int, int]] = set()
        self.collisions: list[Collision] = []

    def update(self, physics: Physics, robots: Mapping[str, SimRobot], now: float):
        """The collisions that began in the last step."""
        touching = set()
        for robot in robots.values():
            for other in physics.touching(robot.body):
                if other in self.names:
                    touching.add((robot.body, other))
        began = [
            Collision(round(now, 6), self.names[a], self.names[b])
            for a, b in sorted(touching - self._touching)
        ]
        self._touching = touching
        self.collisions.extend(began)
        return began


def _clip(value: float, limit: float) -> float:
    return max(-limit, min(limit, value))
