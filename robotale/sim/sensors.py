"""Exteroceptive sensors: an ultrasonic range sensor (a fan of pybullet rays) and a downward
camera whose footprint grows with altitude (a pybullet box query).

Both can report objects of one kind (weeds, targets) on ``/<robot>/detection``
(``geometry_msgs/msg/PointStamped``, ``header.frame_id`` = the object's id, ``point`` = where
it is), every control step the object is in view: the detector a real robot would run on its
camera or sonar. Telling a new object from one seen before is the listener's job.
"""

from __future__ import annotations

import math
from typing import Any

from robotale.sim.messages import header
from robotale.sim.physics import Physics
from robotale.sim.robots import SimRobot
from robotale.sim.worldspec import CameraSpec, RangeSpec

RANGE = "sensor_msgs/msg/Range"
DETECTION = "geometry_msgs/msg/PointStamped"
ULTRASOUND = 0  # sensor_msgs/msg/Range radiation_type


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
        "min_range": 0.02,
        "max_range": spec.max_range,
        "range": round(distance, 4),
    }


def camera_view(physics: Physics, robot: SimRobot, spec: CameraSpec) -> set[int]:
    """The bodies on the ground inside the camera's footprint (nothing below 0.3 m)."""
    pose = robot.pose
    if pose.z < 0.3:
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


def detection_message(now: float, robot: SimRobot, object_id: str, x: float, y: float):
    """A ``geometry_msgs/msg/PointStamped`` naming the object seen."""
    return {
        "header": header(now, object_id),
        "point": {"x": round(x, 4), "y": round(y, 4), "z": 0.0},
    }
