"""Exteroceptive sensors: an ultrasonic range sensor (a fan of pybullet rays) and a downward
camera whose footprint grows with altitude (a pybullet box query).

Both can report objects of one kind (weeds, targets) on ``/<robot>/detection``
(``geometry_msgs/msg/PointStamped``, ``header.frame_id`` = the object's id, ``point`` = where
it is), every control step the object is in view: the detector a real robot would run on its
camera or sonar. Telling a new object from one seen before is the listener's job.

Both are imperfect as configured in the world file, with draws from the run's seed: a range
reading has gaussian ``noise`` and is lost (read as ``max_range``) with probability
``dropout``; the camera detects an object in view with probability ``detection`` less
``falloff`` per metre from the camera, and sees ``false_positives`` phantoms a second
somewhere in its footprint.
"""

from __future__ import annotations

import math
import random
from typing import Any

import numpy as np

from robotale.sim.messages import header
from robotale.sim.physics import Physics
from robotale.sim.robots import SimRobot
from robotale.sim.worldspec import CameraSpec, RangeSpec

RANGE = "sensor_msgs/msg/Range"
DETECTION = "geometry_msgs/msg/PointStamped"
ULTRASOUND = 0  # sensor_msgs/msg/Range radiation_type
MIN_RANGE = 0.02  # metres
MIN_ALTITUDE = 0.3  # metres: a camera lower sees nothing


def sonar(physics: Physics, robot: SimRobot, spec: RangeSpec) -> tuple[float, int]:
    """The distance to the nearest body in the beam (``max_range`` when none) and that body
    (-1 when none)."""
    starts, ends = _beam(robot, spec)
    hits = physics.rays(starts, ends, ignore=robot.body)
    if physics.gui:  # each ray up to what it hits, like the thesis' blue cones
        physics.show(
            f"{robot.name}/range",
            [(a, _along(a, b, f)) for a, b, (_, f) in zip(starts, ends, hits, strict=True)],
        )
    fraction, body = min((f, b) for b, f in hits)
    return fraction * spec.max_range, body


def reading(distance: float, spec: RangeSpec, rng: random.Random) -> float | None:
    """The distance the sensor reports for a true ``distance``; None when the echo is lost."""
    if spec.dropout and rng.random() < spec.dropout:
        return None
    if not spec.noise:
        return distance
    return min(spec.max_range, max(MIN_RANGE, distance + rng.gauss(0.0, spec.noise)))


def _along(start, end, fraction: float) -> tuple[float, ...]:
    return tuple(a + (b - a) * fraction for a, b in zip(start, end, strict=True))


def _beam(robot: SimRobot, spec: RangeSpec):
    """The rays of a range sensor: start and end points."""
    pose = robot.pose
    if spec.direction == "down":
        start = (pose.x, pose.y, pose.z)
        starts, ends = [start], [(pose.x, pose.y, pose.z - spec.max_range)]
    else:
        height = pose.z + robot.spec.size[2] / 2
        front = robot.spec.size[0] / 2
        start = (pose.x + front * math.cos(pose.yaw), pose.y + front * math.sin(pose.yaw), height)
        starts, ends = [], []
        for i in range(spec.rays):
            share = 0.5 if spec.rays == 1 else i / (spec.rays - 1)
            angle = pose.yaw + math.radians(spec.cone) * (2 * share - 1)
            starts.append(start)
            ends.append(
                (
                    start[0] + spec.max_range * math.cos(angle),
                    start[1] + spec.max_range * math.sin(angle),
                    height,
                )
            )
    return starts, ends


def range_message(now: float, robot: SimRobot, spec: RangeSpec, distance: float) -> dict[str, Any]:
    """A ``sensor_msgs/msg/Range``."""
    return {
        "header": header(now, f"{robot.name}/sonar"),
        "radiation_type": ULTRASOUND,
        "field_of_view": 2 * math.radians(spec.cone),
        "min_range": MIN_RANGE,
        "max_range": spec.max_range,
        "range": round(distance, 4),
    }


def camera_view(physics: Physics, robot: SimRobot, spec: CameraSpec) -> set[int]:
    """The bodies on the ground inside the camera's footprint (nothing below 0.3 m)."""
    pose = robot.pose
    if pose.z < MIN_ALTITUDE:
        return set()
    half = pose.z * math.tan(math.radians(spec.fov) / 2)
    if physics.gui:
        corners = [(pose.x + dx * half, pose.y + dy * half, 0.02) for dx, dy in _SQUARE]
        physics.show(
            f"{robot.name}/camera", list(zip(corners, [*corners[1:], corners[0]], strict=True))
        )
    return physics.overlapping(
        (pose.x - half, pose.y - half, -0.05), (pose.x + half, pose.y + half, 0.3)
    )


_SQUARE = ((-1, -1), (1, -1), (1, 1), (-1, 1))


def detected(
    robot: SimRobot, spec: CameraSpec, where: tuple[float, float], rng: random.Random
) -> bool:
    """Whether the camera's detector finds an object at ``where`` in view this frame."""
    if spec.detection >= 1.0 and not spec.falloff:
        return True
    pose = robot.pose
    distance = math.dist((pose.x, pose.y, pose.z), (*where, 0.0))
    return rng.random() < spec.detection - spec.falloff * distance


def phantoms(
    robot: SimRobot, spec: CameraSpec, dt: float, rng: random.Random
) -> list[tuple[float, float]]:
    """Where the detector sees objects that are not there in a frame of ``dt`` seconds (at
    most one a frame: a Bernoulli draw with ``false_positives * dt``)."""
    pose = robot.pose
    if (
        not spec.false_positives
        or pose.z < MIN_ALTITUDE
        or rng.random() >= spec.false_positives * dt
    ):
        return []
    half = pose.z * math.tan(math.radians(spec.fov) / 2)
    return [(pose.x + rng.uniform(-half, half), pose.y + rng.uniform(-half, half))]


def detection_message(now: float, object_id: str, x: float, y: float):
    """A ``geometry_msgs/msg/PointStamped`` naming the object seen."""
    return {
        "header": header(now, object_id),
        "point": {"x": round(x, 4), "y": round(y, 4), "z": 0.0},
    }


class Footprints:
    """The part of the field a robot's camera has seen: a grid of ``cell``-sized squares,
    each marked once any camera footprint (at least :data:`MIN_ALTITUDE` up) covered its
    centre. This, not the cells the robot flew over, is what the robot could find weeds in:
    a drone 1.5 m up with a 90 degree camera sees a 3 m wide strip."""

    def __init__(self, field: tuple[float, float], cell: float = 0.1) -> None:
        self.cell = cell
        self.shape = (max(1, round(field[0] / cell)), max(1, round(field[1] / cell)))
        self.seen: dict[str, np.ndarray] = {}

    def look(self, robot: SimRobot, spec: CameraSpec) -> None:
        """Mark what the camera sees from the robot's pose now."""
        pose = robot.pose
        if pose.z < MIN_ALTITUDE:
            return
        half = pose.z * math.tan(math.radians(spec.fov) / 2)
        grid = self.seen.get(robot.name)
        if grid is None:
            grid = self.seen[robot.name] = np.zeros(self.shape, dtype=bool)
        grid[self._cells(pose.x, half, 0), self._cells(pose.y, half, 1)] = True

    def _cells(self, centre: float, half: float, axis: int) -> slice:
        """The cells whose centres lie within ``half`` of ``centre`` along one axis."""
        low = math.ceil((centre - half) / self.cell - 0.5)
        high = math.floor((centre + half) / self.cell - 0.5)
        size = self.shape[axis]
        return slice(min(size, max(0, low)), min(size, max(0, high + 1)))

    def fractions(self) -> dict[str, float]:
        """Per robot with a camera, the share of the field it has seen (0-1)."""
        return {name: round(float(grid.mean()), 4) for name, grid in sorted(self.seen.items())}
