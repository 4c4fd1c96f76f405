"""The pybullet side of the world: bodies, ray tests, overlap queries and the window.

Robots move kinematically (their pose is set each control step from the commanded velocity),
so pybullet never integrates dynamics: it holds the bodies the sensors see, answers ray tests
(ultrasonic range) and box queries (a camera footprint), and draws the GUI. Each world has its
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
    ) -> int:
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
        return self._body(shape, visual, position, yaw)

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

    def _body(self, shape: int, visual: int, position: Sequence[float], yaw: float) -> int:
        return pybullet.createMultiBody(
            baseMass=0,
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
