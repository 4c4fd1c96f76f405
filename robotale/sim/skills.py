"""The skills call activities run in the simulated missions (and on any robot with the same
topics): GoTo, Explore, TakeOff, Land, ReturnToBase, CutGrass, GetPosition, Fire.

Each follows :mod:`robotale.fame_runtime.skills`: it acts only through the robot's topics and
the clock, takes simulated time, calls ``done(outputs)`` when finished and returns a cancel
function that leaves the robot safe (wheels stopped, blade off, LED off).

======================  =========================================================  ===========
skill                   inputs (defaults)                                          outputs
======================  =========================================================  ===========
GoTo                    x_target, y_target, tolerance (0.2), speed (1.0)           -
ReturnToBase            x_base, y_base (the robot's variables), tolerance, speed   -
TakeOff                 -                                                          -
Land                    -                                                          -
Explore                 x_lower_boundary, y_lower_boundary, x_upper_boundary,      found,
                        y_upper_boundary, swath (2.0), speed (1.0), signal,        x_found,
                        signal_type (geometry_msgs/msg/Vector3), resume_on,        y_found
                        resume_after (60), stop_after (0: never)
CutGrass                force (10.0), duration (3.0)                               -
GetPosition             -                                                          my_x, my_y,
                                                                                   my_z
Fire                    duration (1.0)                                             -
======================  =========================================================  ===========

Explore drives a coverage path (lanes ``swath`` apart) and listens to the robot's
``detection`` topic. For each object it sees it throws the signal named by ``signal`` (if
any) with the object's position, tagged ``<signal>!`` like a throw event; with ``resume_on``
it then holds still until a message on that topic (or ``resume_after`` seconds), tagging the
message it consumed ``<resume_on>?`` with the sender's message id as a catch event would, and
with ``stop_after`` it ends after that many finds.
"""

from __future__ import annotations

import json
import math
from collections import deque
from collections.abc import Callable, Mapping
from typing import Any

from robotale.errors import ModelError
from robotale.fame_runtime.bus import Envelope
from robotale.fame_runtime.skills import Cancel, Done, Robot, Skill
from robotale.fame_runtime.tags import (
    COMPLETE,
    RECEIVE,
    SEND,
    START,
    TAG_TYPE,
    Tag,
    payload_text,
    tag_topic,
)

TWIST = "geometry_msgs/msg/Twist"
EMPTY = "std_msgs/msg/Empty"
ODOM = "nav_msgs/msg/Odometry"
TURN_GAIN = 2.0
SLOW_DOWN = 0.8  # forward speed <= this times the remaining distance
HEADING_WINDOW = 0.6  # radians of heading error beyond which a robot turns on the spot
RANGE = "sensor_msgs/msg/Range"
YIELD_TURN = 1.0  # rad/s: a robot that finds its way blocked turns right on the spot ...
SIDESTEP = 0.6  # metres: ... then drives this far along its new heading before steering back
SAME_OBJECT = 0.25  # metres: detections closer than this are one object


def _number(inputs: Mapping[str, Any], robot: Robot, name: str, default: float | None = None):
    """An input, else the robot's variable of that name, else ``default``."""
    value = inputs.get(name)
    if value is None:
        value = robot.variables.get(name, default)
    if value is None:
        raise ModelError(f"robot {robot.name}: the skill needs the input {name}")
    try:
        return float(value)
    except (TypeError, ValueError):
        raise ModelError(f"robot {robot.name}: the input {name} = {value!r} is no number") from None


class _Pose:
    __slots__ = ("climb", "x", "y", "yaw", "z")

    def __init__(self, odom: Mapping[str, Any]) -> None:
        pose = odom["pose"]["pose"]
        position, orientation = pose["position"], pose["orientation"]
        self.x, self.y, self.z = position["x"], position["y"], position["z"]
        self.yaw = 2 * math.atan2(orientation.get("z", 0.0), orientation.get("w", 1.0))
        self.climb = odom["twist"]["twist"]["linear"].get("z", 0.0)


class _Odometry:
    """Calls ``on_pose`` with every odometry message until closed."""

    def __init__(self, robot: Robot, on_pose: Callable[[_Pose], None]) -> None:
        self._on_pose = on_pose
        self._subscription = robot.subscribe("odom", self._message, ODOM)

    def _message(self, envelope: Envelope) -> None:
        if self._subscription is not None:
            self._on_pose(_Pose(envelope.data))

    def close(self) -> None:
        if self._subscription is not None:
            self._subscription.unsubscribe()
            self._subscription = None


def _twist(robot: Robot, forward: float, turn: float) -> None:
    robot.publish("cmd_vel", {"linear": {"x": forward}, "angular": {"z": turn}}, TWIST)


def _steer(pose: _Pose, target: tuple[float, float], speed: float) -> tuple[float, float]:
    """Differential-drive pursuit: turn towards the target, drive when roughly facing it."""
    dx, dy = target[0] - pose.x, target[1] - pose.y
    error = (math.atan2(dy, dx) - pose.yaw + math.pi) % (2 * math.pi) - math.pi
    turn = TURN_GAIN * error
    if abs(error) > HEADING_WINDOW:
        return 0.0, turn
    return min(speed, SLOW_DOWN * math.hypot(dx, dy)) * math.cos(error), turn


class _Drive:
    """Drives the robot through waypoints; ``arrived()`` after the last one.

    With a ``clearance`` (metres) the robot yields to what its forward range sensor sees
    nearer than that, short of its waypoint: it turns right on the spot until the way is
    clear, drives :data:`SIDESTEP` along its new heading, then heads for the waypoint again.
    Two robots meeting head on both turn right and pass each other, as road users do."""

    def __init__(
        self,
        robot: Robot,
        waypoints,
        speed: float,
        tolerance: float,
        arrived,
        clearance: float = 0.0,
    ) -> None:
        self.robot, self.speed, self.tolerance = robot, speed, tolerance
        self.waypoints = deque(waypoints)
        self.arrived = arrived
        self.paused = False
        self.clearance = clearance
        self.ahead = math.inf  # metres to the nearest thing the range sensor sees
        self.detour: tuple[float, float] | None = None  # where the last sidestep began
        self.ranges = robot.subscribe("range", self._on_range, RANGE) if clearance > 0 else None
        self.odometry = _Odometry(robot, self._on_pose)

    def _on_range(self, envelope: Envelope) -> None:
        data = envelope.data or {}
        reading = float(data.get("range", math.inf))
        self.ahead = reading if reading < float(data.get("max_range", math.inf)) else math.inf

    def _on_pose(self, pose: _Pose) -> None:
        if self.paused or self._yielding(pose):
            return
        while self.waypoints:
            target = self.waypoints[0]
            if math.hypot(target[0] - pose.x, target[1] - pose.y) > self.tolerance:
                _twist(self.robot, *_steer(pose, target, self.speed))
                return
            self.waypoints.popleft()
        self.stop()
        self.arrived()

    def _yielding(self, pose: _Pose) -> bool:
        """Turn away from, then drive past, what blocks the way (True while doing so)."""
        if not self.waypoints or self.clearance <= 0:
            return False
        target = self.waypoints[0]
        if self.ahead < min(self.clearance, math.hypot(target[0] - pose.x, target[1] - pose.y)):
            self.detour = (pose.x, pose.y)
            _twist(self.robot, 0.0, -YIELD_TURN)
            return True
        if self.detour is None:
            return False
        if math.hypot(pose.x - self.detour[0], pose.y - self.detour[1]) < SIDESTEP:
            _twist(self.robot, self.speed, 0.0)
            return True
        self.detour = None
        return False

    def pause(self) -> None:
        self.paused = True
        _twist(self.robot, 0.0, 0.0)

    def resume(self) -> None:
        self.paused = False

    def stop(self) -> None:
        if self.ranges is not None:
            self.ranges.unsubscribe()
            self.ranges = None
        if self.odometry is not None:
            self.odometry.close()
            self.odometry = None
            _twist(self.robot, 0.0, 0.0)


# -- the skills ---------------------------------------------------------------------------------


def go_to(robot: Robot, inputs: Mapping[str, Any], done: Done) -> Cancel:
    target = (_number(inputs, robot, "x_target"), _number(inputs, robot, "y_target"))
    return _go(robot, inputs, target, done)


def return_to_base(robot: Robot, inputs: Mapping[str, Any], done: Done) -> Cancel:
    target = (_number(inputs, robot, "x_base"), _number(inputs, robot, "y_base"))
    return _go(robot, inputs, target, done)


def _go(robot: Robot, inputs, target: tuple[float, float], done: Done) -> Cancel:
    speed = _number(inputs, robot, "speed", 1.0)
    tolerance = _number(inputs, robot, "tolerance", 0.2)
    clearance = _number(inputs, robot, "clearance", 0.0)
    drive = _Drive(robot, [target], speed, tolerance, lambda: done({}), clearance)
    return drive.stop


def take_off(robot: Robot, inputs: Mapping[str, Any], done: Done) -> Cancel:
    return _vertical(robot, "takeoff", lambda pose: pose.z > 0.1 and pose.climb == 0.0, done)


def land(robot: Robot, inputs: Mapping[str, Any], done: Done) -> Cancel:
    return _vertical(robot, "land", lambda pose: pose.z <= 0.0 and pose.climb == 0.0, done)


def _vertical(robot: Robot, command: str, reached, done: Done) -> Cancel:
    """Publish the take-off or land command; done once odometry shows the climb is over."""

    def on_pose(pose: _Pose) -> None:
        if reached(pose):
            odometry.close()
            done({})

    odometry = _Odometry(robot, on_pose)
    robot.publish(command, {}, EMPTY)
    return odometry.close


def cut_grass(robot: Robot, inputs: Mapping[str, Any], done: Done) -> Cancel:
    force = _number(inputs, robot, "force", 10.0)
    blade = "blade_force"
    robot.publish(blade, {"data": force}, "std_msgs/msg/Float64")

    def finish() -> None:
        robot.publish(blade, {"data": 0.0}, "std_msgs/msg/Float64")
        done({})

    timer = robot.clock.call_later(_number(inputs, robot, "duration", 3.0), finish)

    def cancel() -> None:
        timer.cancel()
        robot.publish(blade, {"data": 0.0}, "std_msgs/msg/Float64")

    return cancel


def fire(robot: Robot, inputs: Mapping[str, Any], done: Done) -> Cancel:
    """A red LED, as DINGO fires in the thesis (listing 5.8), then the LED off."""
    color = "std_msgs/msg/ColorRGBA"
    robot.publish("led", {"r": 1.0, "g": 0.0, "b": 0.0, "a": 1.0}, color)

    def off() -> None:
        robot.publish("led", {"r": 0.0, "g": 0.0, "b": 0.0, "a": 0.0}, color)

    def finish() -> None:
        off()
        done({})

    timer = robot.clock.call_later(_number(inputs, robot, "duration", 1.0), finish)

    def cancel() -> None:
        timer.cancel()
        off()

    return cancel


def get_position(robot: Robot, inputs: Mapping[str, Any], done: Done) -> Cancel:
    """The robot's position from its next odometry message."""

    def on_pose(pose: _Pose) -> None:
        odometry.close()
        done({"my_x": pose.x, "my_y": pose.y, "my_z": pose.z})

    odometry = _Odometry(robot, on_pose)
    return odometry.close


def explore(robot: Robot, inputs: Mapping[str, Any], done: Done) -> Cancel:
    return _Explorer(robot, inputs, done).cancel


class _Explorer:
    """A coverage path over a rectangle, reporting what the robot's detector finds."""

    def __init__(self, robot: Robot, inputs: Mapping[str, Any], done: Done) -> None:
        self.robot, self.done = robot, done
        area = [
            _number(inputs, robot, name)
            for name in (
                "x_lower_boundary",
                "y_lower_boundary",
                "x_upper_boundary",
                "y_upper_boundary",
            )
        ]
        swath = _number(inputs, robot, "swath", 2.0)
        self.signal = str(inputs.get("signal") or "")
        self.signal_type = str(inputs.get("signal_type") or "geometry_msgs/msg/Vector3")
        self.resume_on = str(inputs.get("resume_on") or "")
        self.resume_after = _number(inputs, robot, "resume_after", 60.0)
        self.stop_after = int(_number(inputs, robot, "stop_after", 0))
        self.plan = [*area, swath]
        reached, seen = _progress(
            inputs.get("explored") or robot.variables.get("explored"), self.plan
        )
        self.seen = seen  # what an earlier Explore of this area reported: not new
        self.found: list[tuple[float, float]] = []
        self.queue: deque[tuple[float, float]] = deque()
        self.waiting: list[Any] = []  # the resume subscription and timer while held
        self.path = lanes(*area, swath)
        self.drive = _Drive(
            robot, self.path[reached:], _number(inputs, robot, "speed", 1.0), 0.3, self._finish
        )
        self.detections = robot.subscribe("detection", self._detected)

    def _detected(self, envelope: Envelope) -> None:
        point = envelope.data["point"]
        spot = (point["x"], point["y"])
        known = (*self.seen, *self.found, *self.queue)
        if any(math.dist(spot, seen) < SAME_OBJECT for seen in known):
            return  # seen before: a detector reports an object every frame it is in view
        self.queue.append(spot)
        if not self.waiting:
            self._next()

    def _next(self) -> None:
        if not self.queue or self.drive.odometry is None:
            return
        x, y = self.queue.popleft()
        self.found.append((x, y))
        if self.signal:
            throw(self.robot, self.signal, {"x": x, "y": y, "z": 0.0}, self.signal_type)
        if self.resume_on:
            self._hold()
        elif self._enough():
            self._finish()

    def _enough(self) -> bool:
        return bool(self.stop_after) and len(self.found) >= self.stop_after

    def _hold(self) -> None:
        self.drive.pause()
        topic = self.resume_on if self.resume_on.startswith("/") else f"/{self.resume_on}"
        self.waiting = [
            self.robot.subscribe(topic, self._heard),
            self.robot.clock.call_later(self.resume_after, self._resume),
        ]

    def _heard(self, envelope: Envelope) -> None:
        """The message it held for: consumed (a receive tag, as a catch event leaves), and on."""
        if self.waiting:
            receive(self.robot, envelope)
            self._resume()

    def _resume(self) -> None:
        self._release()
        if self._enough():  # the last find answered: end here, still holding
            self._finish()
            return
        self.drive.resume()
        self._next()

    def _release(self) -> None:
        subscription, timer = self.waiting or (None, None)
        self.waiting = []
        if subscription is not None:
            subscription.unsubscribe()
            timer.cancel()

    def _finish(self) -> None:
        reached = len(self.path) - len(self.drive.waypoints)
        self.cancel()
        last = self.found[-1] if self.found else (None, None)
        explored = {
            "plan": self.plan,
            "reached": reached,
            "seen": [list(spot) for spot in (*self.seen, *self.found)],
        }
        self.done(
            {"found": len(self.found), "x_found": last[0], "y_found": last[1], "explored": explored}
        )

    def cancel(self) -> None:
        self._release()
        self.detections.unsubscribe()
        self.drive.stop()


def _progress(explored: Any, plan: list[float]) -> tuple[int, list[tuple[float, float]]]:
    """Where an earlier Explore of the same area and swath stopped: the waypoints it had
    reached and the objects it had reported (none if it explored something else)."""
    if not isinstance(explored, Mapping) or list(explored.get("plan") or ()) != plan:
        return 0, []
    seen = [(float(x), float(y)) for x, y in explored.get("seen") or ()]
    return int(explored.get("reached") or 0), seen


def lanes(
    x_low: float, y_low: float, x_high: float, y_high: float, swath: float
) -> list[tuple[float, float]]:
    """A boustrophedon path: lanes along y, ``swath`` apart, half a swath inside the edges."""
    if x_high <= x_low or y_high <= y_low or swath <= 0:
        raise ModelError(
            f"Explore needs a non-empty area and a positive swath, got x {x_low}..{x_high}, "
            f"y {y_low}..{y_high}, swath {swath}"
        )
    width, depth = x_high - x_low, y_high - y_low
    count = max(1, math.ceil(width / swath - 1e-9))
    step = width / count
    inset = min(swath / 2, depth / 2)
    points = []
    for lane in range(count):
        x = x_low + step * (lane + 0.5)
        ends = [(x, y_low + inset), (x, y_high - inset)]
        points += ends if lane % 2 == 0 else ends[::-1]
    return points


def throw(robot: Robot, signal: str, data: Mapping[str, Any], msgtype: str) -> None:
    """Throw a signal from inside a skill, tagged ``<signal>!`` as a throw event is."""
    name = signal.strip("/")
    new_id = getattr(robot.bus, "new_msg_id", None)
    msg_id = new_id() if new_id else f"m_{robot.name}_{name}_{robot.now()}"
    payload = json.dumps(data, separators=(",", ":"))
    _tag(robot, f"{name}!", START, msg_id, payload)
    robot.bus.publish(f"/{name}", dict(data), msgtype=msgtype, sender=robot.name, msg_id=msg_id)
    _tag(robot, f"{name}!", COMPLETE, msg_id, payload)


def receive(robot: Robot, envelope: Envelope) -> None:
    """Tag a signal a skill consumed, ``<signal>?`` with the sender's message id, as a catch
    event is tagged: every message a robot consumes is a receive in the log."""
    name = envelope.topic.strip("/")
    payload = payload_text(envelope.data)
    for lifecycle in (START, COMPLETE):
        _tag(robot, f"{name}?", lifecycle, envelope.msg_id, payload, RECEIVE)


def _tag(
    robot: Robot, activity: str, lifecycle: str, msg_id: str, payload: str, role: str = SEND
) -> None:
    tag = Tag(robot.clock.now(), robot.name, activity, lifecycle, msg_id, role, payload)
    robot.bus.publish(tag_topic(robot.name), tag, msgtype=TAG_TYPE, sender=robot.name)


SKILLS: dict[str, Skill] = {
    "GoTo": go_to,
    "ReturnToBase": return_to_base,
    "TakeOff": take_off,
    "Land": land,
    "Explore": explore,
    "CutGrass": cut_grass,
    "GetPosition": get_position,
    "Fire": fire,
}
