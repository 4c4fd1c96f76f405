"""The pybullet side of the world: bodies, ray tests, overlap queries, dynamics and the window.

In kinematic mode robots move by having their pose set each control step, so pybullet never
integrates: it holds the bodies the sensors see, answers ray tests (ultrasonic range) and box
queries (a camera footprint), and draws the GUI. In dynamics mode (:meth:`Physics.dynamics`)
ground robots are bodies with mass, pushed by forces and stepped with ``stepSimulation`` at a
fixed rate, so they have inertia and collide (:mod:`robotale.sim.dynamics`). Each world has its
own pybullet client, so several worlds can live in one process.
"""

from __future__ import annotations

import contextlib
import ctypes
import math
import os
import sys
from collections.abc import Iterator, Sequence

from robotale.errors import RobotaleError


@contextlib.contextmanager
def _quiet() -> Iterator[None]:
    """Keep pybullet's C-level chatter ("pybullet build time ...") off stdout and stderr."""
    sys.stdout.flush()
    sys.stderr.flush()
    saved = {fd: os.dup(fd) for fd in (1, 2)}
    try:
        with open(os.devnull, "w") as devnull:
            for fd in saved:
                os.dup2(devnull.fileno(), fd)
            try:
                yield
            finally:
                _libc.fflush(None)  # what C buffered goes to /dev/null too
    finally:
        for fd, copy in saved.items():
            os.dup2(copy, fd)
            os.close(copy)


_libc = ctypes.CDLL(None)


with _quiet():
    import pybullet

Color = tuple[float, float, float, float]
#: a body's position, yaw, linear velocity and yaw rate
Motion = tuple[tuple[float, float, float], float, tuple[float, float, float], float]
GRAVITY = 9.81  # m/s2
_ROBOTS = 4  # the collision group of driven robots (bit 1 is the rays' group)


#: headless clients of this process, emptied and unused
_SPARE: list[int] = []


class Physics:
    """One pybullet client (``DIRECT`` headless, ``GUI`` with a window).

    Headless clients are kept for the next world of the same process once closed (emptied
    with ``resetSimulation``), since connecting costs more than a short run's physics.
    """

    def __init__(self, *, gui: bool = False) -> None:
        self.gui = gui
        self._drawn: dict[str, list[int]] = {}
        if not gui and _SPARE:
            self.client = _SPARE.pop()
            return
        mode = pybullet.GUI if gui else pybullet.DIRECT
        with _quiet():
            self.client = pybullet.connect(mode)
        if self.client < 0:
            raise RobotaleError("pybullet cannot open a window here (is there a display?)")
        if gui:
            pybullet.configureDebugVisualizer(
                pybullet.COV_ENABLE_GUI, 0, physicsClientId=self.client
            )

    def close(self) -> None:
        if self.client < 0:
            return
        if self.connected():
            if self.gui:
                with _quiet():
                    pybullet.disconnect(physicsClientId=self.client)
            else:
                pybullet.resetSimulation(physicsClientId=self.client)
                _SPARE.append(self.client)
        self.client = -1

    def connected(self) -> bool:
        """False once a person closed the window."""
        return self.client >= 0 and pybullet.isConnected(physicsClientId=self.client)

    # -- bodies -----------------------------------------------------------------------------------

    def ground(self, size: tuple[float, float], color: Color) -> int:
        """A flat field with its corner at the origin."""
        half = (size[0] / 2, size[1] / 2, 0.005)
        return self.box(half, (half[0], half[1], -0.005), color, collide=True)

    def box(
        self,
        half_extents: Sequence[float],
        position: Sequence[float],
        color: Color,
        *,
        collide: bool = True,
        yaw: float = 0.0,
        mass: float = 0.0,
    ) -> int:
        """A box; ``mass`` > 0 makes it a dynamic body (static, moved only by placing, if 0)."""
        shape = (
            pybullet.createCollisionShape(
                pybullet.GEOM_BOX, halfExtents=half_extents, physicsClientId=self.client
            )
            if collide
            else -1
        )
        visual = pybullet.createVisualShape(
            pybullet.GEOM_BOX,
            halfExtents=half_extents,
            rgbaColor=color,
            physicsClientId=self.client,
        )
        return self._body(shape, visual, position, yaw, mass)

    def cylinder(
        self, radius: float, height: float, position: Sequence[float], color: Color, collide=True
    ) -> int:
        shape = (
            pybullet.createCollisionShape(
                pybullet.GEOM_CYLINDER, radius=radius, height=height, physicsClientId=self.client
            )
            if collide
            else -1
        )
        visual = pybullet.createVisualShape(
            pybullet.GEOM_CYLINDER,
            radius=radius,
            length=height,
            rgbaColor=color,
            physicsClientId=self.client,
        )
        return self._body(shape, visual, position, 0.0)

    def _body(
        self, shape: int, visual: int, position: Sequence[float], yaw: float, mass: float = 0.0
    ) -> int:
        return pybullet.createMultiBody(
            baseMass=mass,
            baseCollisionShapeIndex=shape,
            baseVisualShapeIndex=visual,
            basePosition=position,
            baseOrientation=_quaternion(yaw),
            physicsClientId=self.client,
        )

    def place(self, body: int, position: Sequence[float], yaw: float) -> None:
        pybullet.resetBasePositionAndOrientation(
            body, position, _quaternion(yaw), physicsClientId=self.client
        )

    # -- dynamics ---------------------------------------------------------------------------------

    def dynamics(self, rate: float) -> None:
        """Integrate at ``rate`` steps a second under gravity (one :meth:`step` = one step)."""
        pybullet.setGravity(0, 0, -GRAVITY, physicsClientId=self.client)
        pybullet.setPhysicsEngineParameter(fixedTimeStep=1.0 / rate, physicsClientId=self.client)

    def floor(self) -> int:
        """An endless invisible ground at height 0: bases and robots may lie outside the
        field, and a body with mass must not fall off its edge."""
        shape = pybullet.createCollisionShape(pybullet.GEOM_PLANE, physicsClientId=self.client)
        return self._body(shape, -1, (0.0, 0.0, 0.0), 0.0)

    def step(self) -> None:
        pybullet.stepSimulation(physicsClientId=self.client)

    def slippery(self, body: int) -> None:
        """A driven robot: no contact friction, since its wheels' grip is modelled by the
        forces pushing it (:mod:`robotale.sim.dynamics`), so the box must neither drag on the
        ground nor be slowed by pybullet's default damping; in the robots' collision group."""
        pybullet.changeDynamics(
            body,
            -1,
            lateralFriction=0.0,
            restitution=0.0,
            linearDamping=0.0,
            angularDamping=0.0,
            physicsClientId=self.client,
        )
        pybullet.setCollisionFilterGroupMask(body, -1, _ROBOTS, -1, physicsClientId=self.client)

    def ghost(self, body: int) -> None:
        """``body`` (a weed driven over) never collides with a driven robot, yet rays (of the
        default group) and box queries still see it."""
        pybullet.setCollisionFilterGroupMask(body, -1, 2, ~_ROBOTS, physicsClientId=self.client)

    def pass_through(self, body: int, other: int) -> None:
        """``body`` and ``other`` never collide (a robot drives over a weed): the group masks
        of :meth:`ghost` do not keep a static body off a dynamic one, a pair filter does."""
        pybullet.setCollisionFilterPair(body, other, -1, -1, 0, physicsClientId=self.client)

    def motion(self, body: int) -> Motion:
        """Position, yaw, linear velocity and yaw rate of a body (two reads of pybullet)."""
        position, orientation = pybullet.getBasePositionAndOrientation(
            body, physicsClientId=self.client
        )
        linear, angular = pybullet.getBaseVelocity(body, physicsClientId=self.client)
        x, y, z, w = orientation
        yaw = math.atan2(2 * (w * z + x * y), 1 - 2 * (y * y + z * z))
        return position, yaw, linear, angular[2]

    def push(
        self, body: int, position: Sequence[float], force: Sequence[float], torque: float
    ) -> None:
        """Apply a force (world frame, at the centre of mass, which is at ``position``) and a
        yaw torque for one step."""
        pybullet.applyExternalForce(
            body, -1, force, position, pybullet.WORLD_FRAME, physicsClientId=self.client
        )
        pybullet.applyExternalTorque(
            body, -1, (0.0, 0.0, torque), pybullet.WORLD_FRAME, physicsClientId=self.client
        )

    def contacts(self) -> list[tuple[int, int]]:
        """The pairs of bodies in contact after the last step, each as pybullet reports it:
        one query for the whole world rather than one per body."""
        points = pybullet.getContactPoints(physicsClientId=self.client)
        return [(point[1], point[2]) for point in points or ()]

    def recolor(self, body: int, color: Color) -> None:
        pybullet.changeVisualShape(body, -1, rgbaColor=color, physicsClientId=self.client)

    def remove(self, body: int) -> None:
        pybullet.removeBody(body, physicsClientId=self.client)

    # -- sensing ----------------------------------------------------------------------------------

    def rays(
        self, starts: Sequence[Sequence[float]], ends: Sequence[Sequence[float]], ignore: int
    ) -> list[tuple[int, float]]:
        """(body hit or -1, fraction of the ray) for each ray, skipping the body ``ignore``."""
        hits = pybullet.rayTestBatch(starts, ends, physicsClientId=self.client)
        out = []
        for start, end, hit in zip(starts, ends, hits, strict=True):
            body, fraction = hit[0], hit[2]
            if body == ignore:  # the ray started inside its own robot: look past it
                body, fraction = self._past(start, end, ignore)
            out.append((body, fraction if body >= 0 else 1.0))
        return out

    def _past(self, start, end, ignore: int) -> tuple[int, float]:
        hits = pybullet.rayTestBatch([start], [end], reportHitNumber=4, physicsClientId=self.client)
        found = [(h[2], h[0]) for h in hits if h[0] >= 0 and h[0] != ignore]
        if not found:
            return -1, 1.0
        fraction, body = min(found)
        return body, fraction

    def overlapping(self, low: Sequence[float], high: Sequence[float]) -> set[int]:
        """The bodies whose bounding boxes overlap the box from ``low`` to ``high``."""
        found = pybullet.getOverlappingObjects(low, high, physicsClientId=self.client)
        return {body for body, _ in found or ()}

    def show(self, key: str, segments: Sequence[tuple[Sequence[float], Sequence[float]]]) -> None:
        """Draw (or move) the line segments named ``key`` in the window (a sensor's view)."""
        drawn = self._drawn.setdefault(key, [])
        for index, (start, end) in enumerate(segments):
            replace = drawn[index] if index < len(drawn) else -1
            item = pybullet.addUserDebugLine(
                start,
                end,
                lineColorRGB=(0.2, 0.4, 1.0),
                lineWidth=2.0,
                replaceItemUniqueId=replace,
                physicsClientId=self.client,
            )
            if replace < 0:
                drawn.append(item)

    def follow(self, position: Sequence[float]) -> None:
        """Keep the window's camera on a point."""
        pybullet.resetDebugVisualizerCamera(
            cameraDistance=14,
            cameraYaw=0,
            cameraPitch=-60,
            cameraTargetPosition=position,
            physicsClientId=self.client,
        )


def _quaternion(yaw: float) -> tuple[float, float, float, float]:
    return (0.0, 0.0, math.sin(yaw / 2), math.cos(yaw / 2))
