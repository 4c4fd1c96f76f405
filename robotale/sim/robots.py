"""Simulated robots: bodies driven by velocity commands, reached only through topics.

A ground robot (tractor, REX, DINGO) is a differential drive: ``/<robot>/cmd_vel`` gives its
forward speed (``linear.x``) and turn rate (``angular.z``). A drone takes off on
``/<robot>/takeoff`` and lands on ``/<robot>/land`` (``std_msgs/msg/Empty``), climbing to its
altitude, and while flying obeys ``cmd_vel`` in its body frame like the Tello of the thesis.
Each control step the pose is integrated from the commands, clipped to the robot's limits, and
set on its pybullet body (in dynamics mode a ground robot's pose comes from pybullet instead,
:mod:`robotale.sim.dynamics`); a robot whose battery is empty stops (a drone drops to the ground).
A drone also serves the Tello driver's ``tello_action`` service the thesis' scripts call,
as the topics ``/<robot>/tello_action/request`` (``cmd``: ``takeoff``, ``land``) and
``/<robot>/tello_action/response`` (``rc``: 1 done, 3 busy or unknown).
Actuators: ``/<robot>/blade_force`` (``std_msgs/msg/Float64``, > 0 cuts) and ``/<robot>/led``
(``std_msgs/msg/ColorRGBA``).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any

from robotale.fame_runtime.bus import Bus, Envelope
from robotale.sim.battery import Battery
from robotale.sim.messages import header
from robotale.sim.physics import Physics
from robotale.sim.worldspec import BaseSpec, RobotSpec

ODOM = "nav_msgs/msg/Odometry"
BATTERY = "sensor_msgs/msg/BatteryState"
TWIST = "geometry_msgs/msg/Twist"
EMPTY = "std_msgs/msg/Empty"
FLOAT64 = "std_msgs/msg/Float64"
COLOR = "std_msgs/msg/ColorRGBA"
TELLO_ACTION = "tello_msgs/srv/TelloAction"
TELLO_OK, TELLO_BUSY = 1, 3  # tello_msgs/srv/TelloAction response codes

LANDED, CLIMBING, FLYING, DESCENDING = "landed", "climbing", "flying", "descending"
CHARGER_REACH = 0.5  # metres from its charging spot a robot still charges


@dataclass
class Pose:
    x: float
    y: float
    yaw: float
    z: float = 0.0


@dataclass
class SimRobot:
    """One robot's body, battery and actuators."""

    name: str
    spec: RobotSpec
    base: BaseSpec
    pose: Pose
    battery: Battery
    home: tuple[float, float]  # its charging spot on its base
    body: int = -1
    alive: bool = True
    flight: str = LANDED
    blade: float = 0.0
    led: tuple[float, float, float, float] = (0.0, 0.0, 0.0, 0.0)
    speed: float = 0.0  # m/s actually moved in the last step
    driven: bool = False  # its pose comes from the physics (dynamics mode), not from move()
    thrust: bool = False  # a drone in dynamics mode: its rotors accelerate it (dynamics.fly)
    velocity: tuple[float, float] = (0.0, 0.0)  # m/s in the field's frame (thrust only)
    drift: tuple[float, float] = (0.0, 0.0)  # metres its odometry is off, x and y
    _command: tuple[float, float, float] = (0.0, 0.0, 0.0)  # forward, turn, climb
    _subscriptions: list[Any] = field(default_factory=list)

    @property
    def flies(self) -> bool:
        return self.spec.kind == "drone"

    @property
    def airborne(self) -> bool:
        return self.flies and self.flight != LANDED

    def topic(self, name: str) -> str:
        return f"/{self.name}/{name}"

    # -- actuators --------------------------------------------------------------------------------

    def connect(self, bus: Bus) -> None:
        """Subscribe the robot's drivers to its command topics."""
        wanted = {"cmd_vel": (TWIST, self._cmd_vel)}
        if self.flies:
            wanted["takeoff"] = (EMPTY, self._takeoff)
            wanted["land"] = (EMPTY, self._land)
            wanted["tello_action/request"] = (TELLO_ACTION, lambda e: self._tello(bus, e))
        if self.spec.blade:
            wanted["blade_force"] = (FLOAT64, self._blade)
        if self.spec.led:
            wanted["led"] = (COLOR, self._led)
        for name, (msgtype, callback) in wanted.items():
            self._subscriptions.append(
                bus.subscribe(self.topic(name), callback, msgtype=msgtype, owner=self.name)
            )

    def disconnect(self) -> None:
        for subscription in self._subscriptions:
            subscription.unsubscribe()
        self._subscriptions.clear()

    def _cmd_vel(self, envelope: Envelope) -> None:
        data = envelope.data or {}
        linear, angular = data.get("linear") or {}, data.get("angular") or {}
        self._command = (
            float(linear.get("x", 0.0)),
            float(angular.get("z", 0.0)),
            float(linear.get("z", 0.0)),
        )

    def _takeoff(self, _: Envelope) -> None:
        if self.flight in (LANDED, DESCENDING) and not self.battery.empty:
            self.flight = CLIMBING

    def _land(self, _: Envelope) -> None:
        if self.flight in (CLIMBING, FLYING):
            self.flight = DESCENDING
            self._command = (0.0, 0.0, 0.0)

    def _tello(self, bus: Bus, envelope: Envelope) -> None:
        """The Tello driver's action service: ``takeoff`` and ``land`` do what the topics do;
        anything else (``rc`` commands, flips) is answered busy, as the driver does."""
        command = str((envelope.data or {}).get("cmd", "")).strip().lower()
        actions = {"takeoff": self._takeoff, "land": self._land}
        if command in actions:
            actions[command](envelope)
        rc = TELLO_OK if command in actions else TELLO_BUSY
        bus.publish(
            self.topic("tello_action/response"), {"rc": rc}, msgtype=TELLO_ACTION, sender=self.name
        )

    def _blade(self, envelope: Envelope) -> None:
        self.blade = float((envelope.data or {}).get("data", 0.0))

    def _led(self, envelope: Envelope) -> None:
        data = envelope.data or {}
        self.led = tuple(float(data.get(k, 0.0)) for k in "rgba")  # type: ignore[assignment]

    # -- motion -----------------------------------------------------------------------------------

    def move(self, dt: float) -> None:
        """Integrate one control step from the commands (nothing moves once dead or empty)."""
        if not self.alive:
            self.speed = 0.0
            return
        if self.battery.empty:
            self._command = (0.0, 0.0, 0.0)
            self.blade = 0.0
            if self.flies and self.pose.z > 0:
                self.pose.z, self.flight = 0.0, LANDED  # it falls
                self.velocity = (0.0, 0.0)
        if self.driven:
            return  # the physics moved it (robotale.sim.dynamics)
        forward, turn = self._limited()
        if self.flies:
            self._fly_vertically(dt)
        pose = self.pose
        if self.thrust:  # its rotors move it across (robotale.sim.dynamics.fly)
            pose.yaw = _wrap(pose.yaw + turn * dt)
            return
        pose.yaw = _wrap(pose.yaw + turn * dt)
        pose.x += forward * math.cos(pose.yaw) * dt
        pose.y += forward * math.sin(pose.yaw) * dt
        self.speed = abs(forward)

    def wanted(self) -> tuple[float, float]:
        """The forward speed and turn rate its drive aims at (nothing once dead or empty)."""
        if not self.alive or self.battery.empty:
            return 0.0, 0.0
        return self._limited()

    def _limited(self) -> tuple[float, float]:
        if self.flies and self.flight != FLYING:
            return 0.0, 0.0
        forward, turn, _ = self._command
        limit, turn_limit = self.spec.max_speed, self.spec.max_turn
        return max(-limit, min(limit, forward)), max(-turn_limit, min(turn_limit, turn))

    def _fly_vertically(self, dt: float) -> None:
        pose, climb = self.pose, self.spec.climb * dt
        if self.flight == CLIMBING:
            pose.z = min(self.spec.altitude, pose.z + climb)
            if pose.z >= self.spec.altitude:
                self.flight = FLYING
        elif self.flight == DESCENDING:
            pose.z = max(0.0, pose.z - climb)
            if pose.z <= 0.0:
                self.flight = LANDED

    def wander(self, dt: float, rng) -> None:
        """Odometry drifts: a random walk of ``odom_drift`` metres per root metre travelled."""
        travelled = self.speed * dt
        if not self.spec.odom_drift or travelled <= 0:
            return
        spread = self.spec.odom_drift * math.sqrt(travelled)
        self.drift = (self.drift[0] + rng.gauss(0, spread), self.drift[1] + rng.gauss(0, spread))

    def on_charger(self) -> bool:
        """Still on its charging spot, or anywhere on its base (a drone: landed)."""
        base = self.base
        if not base.charging or self.speed > 1e-3 or (self.flies and self.flight != LANDED):
            return False
        x, y = self.pose.x, self.pose.y
        at_home = math.hypot(x - self.home[0], y - self.home[1]) <= CHARGER_REACH
        return at_home or math.hypot(x - base.position[0], y - base.position[1]) <= base.radius

    # -- what its sensors say ---------------------------------------------------------------------

    def odometry(self, now: float) -> dict[str, Any]:
        """A ``nav_msgs/msg/Odometry``: pose in the field's frame, velocity in the body frame."""
        pose = self.pose
        forward, turn = self.wanted()
        climb = 0.0
        if self.flight == CLIMBING:
            climb = self.spec.climb
        elif self.flight == DESCENDING:
            climb = -self.spec.climb
        return {
            "header": header(now, "odom"),
            "child_frame_id": f"{self.name}/base_link",
            "pose": {
                "pose": {
                    "position": {
                        "x": round(pose.x + self.drift[0], 6),
                        "y": round(pose.y + self.drift[1], 6),
                        "z": round(pose.z, 6),
                    },
                    "orientation": {"z": math.sin(pose.yaw / 2), "w": math.cos(pose.yaw / 2)},
                }
            },
            "twist": {"twist": {"linear": {"x": forward, "z": climb}, "angular": {"z": turn}}},
        }


def _wrap(angle: float) -> float:
    return (angle + math.pi) % (2 * math.pi) - math.pi


def place(physics: Physics, robot: SimRobot) -> None:
    """Put the robot's body where its pose says (the body's centre above the ground)."""
    height = robot.spec.size[2]
    physics.place(
        robot.body, (robot.pose.x, robot.pose.y, robot.pose.z + height / 2), robot.pose.yaw
    )
