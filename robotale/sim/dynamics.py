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
from collections.abc import Iterable, Mapping
from dataclasses import dataclass

from robotale.sim.physics import GRAVITY, Motion, Physics
from robotale.sim.robots import SimRobot

COLLISION = "std_msgs/msg/String"
FLIGHT_SUBSTEPS = 5  # integration steps of a drone's flight per control step
STANDING = 1e-6  # m/s and rad/s: slower than this a body stands still


@dataclass(frozen=True)
class Collision:
    time: float
    robot: str
    other: str  # a robot's name or an obstacle's


@dataclass(frozen=True)
class Drive:
    """A ground robot's drive, worked out once from its spec rather than every physics step."""

    mass: float
    max_force: float
    max_torque: float
    grip: float  # N: the most force the tyres pass on, forward and sideways together
    inertia: float  # kg m2: the box's moment of inertia about its vertical axis

    @classmethod
    def of(cls, robot: SimRobot) -> Drive:
        spec = robot.spec
        length, width, _ = spec.size
        return cls(
            mass=spec.mass,
            max_force=spec.max_force,
            max_torque=spec.max_torque,
            grip=spec.friction * spec.mass * GRAVITY,
            inertia=spec.mass * (length**2 + width**2) / 12,
        )


def drive(physics: Physics, robot: SimRobot, motors: Drive, motion: Motion, dt: float) -> bool:
    """Push ``robot``'s body for one physics step of ``dt`` seconds towards its command, from
    its ``motion`` after the last step; False if it stands and is told to stand (no push)."""
    position, yaw, velocity, yaw_rate = motion
    forward, turn = robot.wanted()
    if forward == 0.0 and turn == 0.0 and standing(motion):
        # nothing slides a standing body (no friction, no damping): it needs no force until
        # something moves it, and then the drive holds it again at the next step
        return False
    cos, sin = math.cos(yaw), math.sin(yaw)
    along = velocity[0] * cos + velocity[1] * sin
    across = velocity[1] * cos - velocity[0] * sin
    push = _clip(motors.mass * (forward - along) / dt, motors.max_force)
    hold = -motors.mass * across / dt
    total = math.hypot(push, hold)
    if total > motors.grip:  # the tyres slip: the force they pass on is capped by friction
        push, hold = push * motors.grip / total, hold * motors.grip / total
    force = (push * cos - hold * sin, push * sin + hold * cos, 0.0)
    torque = _clip(motors.inertia * (turn - yaw_rate) / dt, motors.max_torque)
    physics.push(robot.body, position, force, torque)
    return True


def standing(motion: Motion) -> bool:
    """The body neither moves nor turns."""
    _, _, velocity, yaw_rate = motion
    return max(abs(velocity[0]), abs(velocity[1]), abs(velocity[2]), abs(yaw_rate)) < STANDING


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


def follow(robot: SimRobot, motion: Motion) -> None:
    """Take the robot's pose and speed from its body's ``motion`` after a step."""
    position, yaw, velocity, _ = motion
    robot.pose.x, robot.pose.y, robot.pose.yaw = position[0], position[1], yaw
    robot.speed = math.hypot(velocity[0], velocity[1])


class Contacts:
    """Which robot touches which body, to report each contact once, when it begins."""

    def __init__(self, names: Mapping[int, str], robots: Iterable[int] = ()) -> None:
        self.names = names  # body -> name, for robots and obstacles (others are ignored)
        self.robots = frozenset(robots)  # the driven robots' bodies
        self._touching: set[tuple[int, int]] = set()
        self.collisions: list[Collision] = []

    def update(self, pairs: Iterable[tuple[int, int]], now: float) -> list[Collision]:
        """The collisions that began in the last step, from every pair of bodies in contact
        (:meth:`Physics.contacts`): a robot's contact is reported for the robot, and a contact
        of two robots for each of them."""
        touching = set()
        for a, b in pairs:
            if a in self.robots and b in self.names:
                touching.add((a, b))
            if b in self.robots and a in self.names:
                touching.add((b, a))
        began = [
            Collision(round(now, 6), self.names[a], self.names[b])
            for a, b in sorted(touching - self._touching)
        ]
        self._touching = touching
        self.collisions.extend(began)
        return began


def _clip(value: float, limit: float) -> float:
    return max(-limit, min(limit, value))
