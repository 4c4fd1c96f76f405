"""The simulated world: a field with bases, weeds or targets, and robots, stepped on the
mission's :class:`~robotale.fame_runtime.clock.SimClock` at a modest control rate.

Every control step moves each robot from its last command, drains or charges its battery, and
publishes what its sensors read on its topics (the thesis' names):

=========================  =================================  ==============================
topic                      type                               when
=========================  =================================  ==============================
``/<robot>/odom``          ``nav_msgs/msg/Odometry``          every control step
``/<robot>/battery``       ``sensor_msgs/msg/BatteryState``   once a second (percentage 0-1)
``/<robot>/low_battery``   ``std_msgs/msg/Empty``             below the threshold, repeated
``/<robot>/range``         ``sensor_msgs/msg/Range``          every control step (if fitted)
``/<robot>/detection``     ``geometry_msgs/msg/PointStamped`` each step an object is seen
``/<camera signal>``       ``geometry_msgs/msg/Vector3``      once per new object (if named)
``/<robot>/collision``     ``std_msgs/msg/String``            a contact begins (dynamics)
=========================  =================================  ==============================

With ``dynamics: true`` ground robots are pushed by their drives and pybullet steps the world
``physics_rate`` times a second (:mod:`robotale.sim.dynamics`); the control steps then read
their poses from the physics. Drones then fly by thrust against drag (``dynamics.fly``).

A tractor's blade cuts the weeds within its radius while ``blade_force`` > 0; a robot whose
LED turns red destroys the targets within :data:`FIRE_RANGE`. The engines never see this
module: they reach the robots through the bus only.
"""

from __future__ import annotations

import math
import random
from dataclasses import dataclass
from typing import Any

from robotale.errors import RobotaleError
from robotale.fame_runtime.bus import Bus
from robotale.fame_runtime.clock import SimClock
from robotale.sim import dynamics, sensors
from robotale.sim.battery import Battery
from robotale.sim.physics import Physics
from robotale.sim.robots import BATTERY, EMPTY, ODOM, Pose, SimRobot, place
from robotale.sim.setup import Placed, RobotStart, Setup
from robotale.sim.worldspec import ObjectsSpec, RobotSpec, World

VECTOR3 = "geometry_msgs/msg/Vector3"
FIRE_RANGE = 1.5  # metres
BATTERY_PERIOD = 1.0  # seconds between battery messages
FIELD_COLOR = (0.55, 0.45, 0.3, 1.0)
CUT_COLOR = (0.35, 0.25, 0.15, 1.0)
DESTROYED_COLOR = (0.1, 0.1, 0.1, 1.0)


class WindowClosed(RobotaleError):
    """The person watching closed pybullet's window."""


@dataclass
class Thing:
    """A weed or a target."""

    kind: str
    id: str
    x: float
    y: float
    body: int
    state: str = "present"  # present | cut | destroyed
    found_by: str = ""
    found_at: float | None = None
    done_by: str = ""  # who cut or destroyed it
    done_at: float | None = None


class SimWorld:
    def __init__(
        self,
        world: World,
        setup: Setup,
        *,
        clock: SimClock,
        bus: Bus,
        gui: bool = False,
        silent: frozenset[str] = frozenset(),
    ) -> None:
        """``silent``: camera signals the mission's skills throw themselves (so the world
        does not throw them a second time)."""
        self.spec, self.setup = world, setup
        self.silent = silent
        self._signalled: set[tuple[str, int]] = set()  # (robot, object) a signal announced
        self.clock, self.bus = clock, bus
        self.dt = 1.0 / world.control_rate
        self.contacts = dynamics.Contacts({})
        self.noise = random.Random(setup.seed)  # the sensors' draws, repeatable per run
        self._phantoms = 0
        self.footprints = sensors.Footprints(world.field)
        self.physics = Physics(gui=gui)
        try:
            self._build()
        except BaseException:
            self.physics.close()
            raise

    def _build(self) -> None:
        world, physics = self.spec, self.physics
        if world.dynamics:
            physics.dynamics(world.physics_rate)
            physics.floor()
        field = physics.ground(world.field, FIELD_COLOR)
        names = {}
        for obstacle in world.obstacles:
            half = [size / 2 for size in obstacle.size]
            position = (*obstacle.position, half[2])
            body = physics.box(half, position, obstacle.color, yaw=math.radians(obstacle.yaw))
            names[body] = obstacle.name
        for base in world.bases.values():
            physics.cylinder(base.radius, 0.01, (*base.position, 0.005), base.color, collide=False)
        specs = {name: spec for spec in world.robots for name in spec.names()}
        self.robots = {s.name: self._robot(s, specs[s.name]) for s in self.setup.robots}
        names.update({robot.body: name for name, robot in self.robots.items()})
        for robot in self.robots.values():
            if robot.driven:  # the floor carries it: one resting contact to solve, not two
                physics.pass_through(robot.body, field)
        driven = [robot.body for robot in self.robots.values() if robot.driven]
        self.contacts = dynamics.Contacts(names, driven)
        looks = {o.kind: o for o in world.objects}
        self.things: dict[int, Thing] = {}
        for placed in self.setup.objects:
            thing = self._thing(placed, looks[placed.kind])
            self.things[thing.body] = thing
            for robot in self.robots.values():
                if robot.driven:
                    physics.pass_through(robot.body, thing.body)
        if physics.gui:
            physics.follow((world.field[0] / 2, world.field[1] / 2, 0.0))

    def _robot(self, start: RobotStart, spec: RobotSpec) -> SimRobot:
        battery = spec.battery
        robot = SimRobot(
            name=start.name,
            spec=spec,
            base=self.spec.bases[spec.base],
            pose=Pose(start.x, start.y, start.yaw),
            battery=Battery(
                start.level,
                start.drain,
                start.move_drain,
                battery.charge,
                battery.low,
                battery.warn_period,
                start.flight_drain,
            ),
            home=start.home,
        )
        half = [size / 2 for size in spec.size]
        robot.driven = self.spec.dynamics and not robot.flies
        robot.thrust = self.spec.dynamics and robot.flies
        mass = spec.mass if robot.driven else 0.0
        robot.body = self.physics.box(
            half, (start.x, start.y, half[2]), spec.color, yaw=start.yaw, mass=mass
        )
        if robot.driven:
            self.physics.slippery(robot.body)
        robot.connect(self.bus)
        return robot

    def _thing(self, placed: Placed, look: ObjectsSpec) -> Thing:
        if placed.kind == "weed":
            body = self.physics.cylinder(look.size / 2, 0.1, (placed.x, placed.y, 0.05), look.color)
        else:
            half = look.size / 2
            body = self.physics.box((half, half, half), (placed.x, placed.y, half), look.color)
        if self.spec.dynamics:  # robots drive over weeds and beside targets, never into them
            self.physics.ghost(body)
        return Thing(placed.kind, placed.id, placed.x, placed.y, body)

    # -- running ----------------------------------------------------------------------------------

    def start(self) -> None:
        """Start each robot's control loop at its phase: it reads its sensors, publishes and
        moves every ``1 / control_rate`` seconds."""
        now = self.clock.now()
        for start in self.setup.robots:
            robot = self.robots[start.name]
            self.clock.call_at(now + start.phase * self.dt, self._loop(robot, now))
        if self.spec.dynamics:
            self.clock.call_at(now, self._physics_loop())

    def close(self) -> None:
        for robot in self.robots.values():
            robot.disconnect()
        self.physics.close()

    def _loop(self, robot: SimRobot, began: float):
        state = {"battery_due": began, "dt": 0.0}

        def tick() -> None:
            if self.physics.gui and not self.physics.connected():
                raise WindowClosed("the pybullet window was closed; the run stopped")
            if not robot.alive:
                return  # a dead robot's loop stops
            now = self.clock.now()
            battery_due = now >= state["battery_due"] - 1e-9
            if battery_due:
                state["battery_due"] = now + BATTERY_PERIOD
            self._step(robot, now, state["dt"], battery_due)
            state["dt"] = self.dt
            self.clock.call_later(self.dt, tick)

        return tick

    def _physics_loop(self):
        """Step pybullet at the world's physics rate: drives push, bodies move and collide.
        Each body's motion is read once a step and serves both the robot's pose and the
        next step's drive; contacts are one query for the world. A step in which every
        driven body stands and is told to stand is skipped: it would change nothing (the
        other bodies are static or placed, and nothing stands on them to fall)."""
        step = 1.0 / self.spec.physics_rate
        driven = [robot for robot in self.robots.values() if robot.driven]
        motors = [dynamics.Drive.of(robot) for robot in driven]
        physics = self.physics
        motions = [physics.motion(robot.body) for robot in driven]

        def tick() -> None:
            pushed = [
                dynamics.drive(physics, robot, drive, motion, step)
                for robot, drive, motion in zip(driven, motors, motions, strict=True)
            ]
            if any(pushed) or not all(map(dynamics.standing, motions)):
                integrate()
            self.clock.call_later(step, tick)

        def integrate() -> None:
            physics.step()
            for index, robot in enumerate(driven):
                motions[index] = physics.motion(robot.body)
                dynamics.follow(robot, motions[index])
            for collision in self.contacts.update(physics.contacts(), self.clock.now()):
                self._collided(collision)

        return tick

    def _collided(self, collision: dynamics.Collision) -> None:
        robot = self.robots[collision.robot]
        if robot.alive:
            self._publish(robot, "collision", {"data": collision.other}, dynamics.COLLISION)

    def _step(self, robot: SimRobot, now: float, dt: float, battery_due: bool) -> None:
        robot.move(dt)
        if robot.thrust:
            dynamics.fly(robot, dt)
        robot.wander(dt, self.noise)
        if not robot.driven:
            place(self.physics, robot)
        on_charger = robot.on_charger()
        if robot.battery.step(dt, robot.speed, on_charger, now, robot.airborne):
            self._publish(robot, "low_battery", {}, EMPTY)
        self._publish(robot, "odom", robot.odometry(now), ODOM)
        if battery_due:
            self._publish(robot, "battery", robot.battery.message(now, robot.name), BATTERY)
        self._sense(robot, now)
        self._act(robot, now)

    def _publish(self, robot: SimRobot, name: str, data: Any, msgtype: str) -> None:
        self.bus.publish(robot.topic(name), data, msgtype=msgtype, sender=robot.name)

    def _sense(self, robot: SimRobot, now: float) -> None:
        spec = robot.spec
        if spec.range is not None:
            self._sonar(robot, spec.range, now)
        if spec.camera is not None:
            camera = spec.camera
            self.footprints.look(robot, camera)
            seen = {
                body
                for body in sensors.camera_view(self.physics, robot, camera)
                if body not in self.things
                or sensors.detected(robot, camera, self._where(body), self.noise)
            }
            self._detected(robot, seen, camera.detects, now)
            if camera.signal and camera.signal not in self.silent:
                self._announce(robot, seen, camera)
            for x, y in sensors.phantoms(robot, camera, self.dt, self.noise):
                self._phantom(robot, camera, x, y, now)

    def _where(self, body: int) -> tuple[float, float]:
        thing = self.things[body]
        return thing.x, thing.y

    def _sonar(self, robot: SimRobot, spec, now: float) -> None:
        distance, body = sensors.sonar(self.physics, robot, spec)
        measured = sensors.reading(distance, spec, self.noise)
        reported = spec.max_range if measured is None else measured
        self._publish(
            robot, "range", sensors.range_message(now, robot, spec, reported), sensors.RANGE
        )
        if measured is not None and spec.detects and measured <= spec.detect_distance:
            self._detected(robot, {body}, spec.detects, now)

    def _phantom(self, robot: SimRobot, camera, x: float, y: float, now: float) -> None:
        """A false positive: detected (and announced) like an object, though nothing is there."""
        self._phantoms += 1
        name = f"phantom_{self._phantoms}"
        self._publish(
            robot, "detection", sensors.detection_message(now, name, x, y), sensors.DETECTION
        )
        if camera.signal and camera.signal not in self.silent:
            point = {"x": round(x, 4), "y": round(y, 4), "z": 0.0}
            self.bus.publish(f"/{camera.signal}", point, msgtype=VECTOR3, sender=robot.name)

    def _announce(self, robot: SimRobot, bodies: set[int], camera) -> None:
        """The detector's signal, once per object this robot sees (the thesis' drone tells
        the mission ``weed_found`` with where the weed is)."""
        for body in sorted(bodies):
            thing = self.things.get(body)
            if thing is None or thing.kind != camera.detects or thing.state != "present":
                continue
            if (robot.name, body) in self._signalled:
                continue
            self._signalled.add((robot.name, body))
            point = {"x": round(thing.x, 4), "y": round(thing.y, 4), "z": 0.0}
            self.bus.publish(f"/{camera.signal}", point, msgtype=VECTOR3, sender=robot.name)

    def _detected(self, robot: SimRobot, bodies: set[int], kind: str, now: float) -> None:
        for body in sorted(bodies):
            thing = self.things.get(body)
            if thing is None or thing.kind != kind or thing.state != "present":
                continue
            if not thing.found_by:
                thing.found_by, thing.found_at = robot.name, now
            message = sensors.detection_message(now, thing.id, thing.x, thing.y)
            self._publish(robot, "detection", message, sensors.DETECTION)

    def _act(self, robot: SimRobot, now: float) -> None:
        if robot.blade > 0:
            self._affect(robot, "weed", robot.spec.blade_radius, "cut", CUT_COLOR, now)
        red, green, blue, _ = robot.led
        if red > 0.5 and green < 0.5 and blue < 0.5:
            self._affect(robot, "target", FIRE_RANGE, "destroyed", DESTROYED_COLOR, now)

    def _affect(self, robot: SimRobot, kind: str, reach: float, state: str, color, now) -> None:
        for thing in self.things.values():
            if thing.kind != kind or thing.state != "present":
                continue
            if math.hypot(thing.x - robot.pose.x, thing.y - robot.pose.y) <= reach:
                thing.state, thing.done_by, thing.done_at = state, robot.name, now
                self.physics.recolor(thing.body, color)

    def position(self, name: str) -> tuple[float, float] | None:
        """Where a robot is (for the network model's distances); None for anything else."""
        robot = self.robots.get(name)
        return None if robot is None else (robot.pose.x, robot.pose.y)

    # -- faults -----------------------------------------------------------------------------------

    def kill(self, name: str) -> None:
        """The robot dies: it stops where it is and publishes nothing more."""
        robot = self.robots[name]
        robot.alive = False
        robot.disconnect()

    def drain(self, name: str, per_second: float) -> None:
        """The robot's battery starts emptying at ``per_second`` (0-1 per second)."""
        self.robots[name].battery.fault_drain = per_second

    # -- the outcome ------------------------------------------------------------------------------

    def report(self, start: float) -> dict[str, Any]:
        """What happened to the objects and the robots, for the run's manifest."""
        things = sorted(self.things.values(), key=lambda t: (t.kind, _number(t.id)))
        counts: dict[str, dict[str, int]] = {}
        for thing in things:
            count = counts.setdefault(thing.kind + "s", {"total": 0, "found": 0, "done": 0})
            count["total"] += 1
            count["found"] += bool(thing.found_by)
            count["done"] += thing.state != "present"
        return {
            "objects": [
                {
                    "id": t.id,
                    "kind": t.kind,
                    "x": round(t.x, 4),
                    "y": round(t.y, 4),
                    "state": t.state,
                    "found_by": t.found_by,
                    "found_after": _since(t.found_at, start),
                    "done_by": t.done_by,
                    "done_after": _since(t.done_at, start),
                }
                for t in things
            ],
            "counts": counts,
            # the share of the field each camera saw (not the cells its robot passed over)
            "coverage": {"cell": self.footprints.cell, "seen": self.footprints.fractions()},
            "collisions": [
                {"after": _since(c.time, start), "robot": c.robot, "other": c.other}
                for c in self.contacts.collisions
            ],
            "robots_final": {
                name: {
                    "x": round(r.pose.x, 4),
                    "y": round(r.pose.y, 4),
                    "z": round(r.pose.z, 4),
                    "battery": round(r.battery.level, 4),
                    "alive": r.alive,
                }
                for name, r in self.robots.items()
            },
        }


def _since(moment: float | None, start: float) -> float | None:
    return None if moment is None else round(moment - start, 3)


def _number(identifier: str) -> int:
    tail = identifier.rsplit("_", 1)[-1]
    return int(tail) if tail.isdigit() else 0
