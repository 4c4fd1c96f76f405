"""The skills of the ``stop`` scenario (thesis 5.3.5): a car drives at a wall and stops once
its ultrasonic sensor reads less than ``stop_range``.

- ``Drive`` commands a forward speed on ``cmd_vel`` and is done at once: the wheels keep the
  command (the FAME variant's model decides when to stop, and sends the stop through Drive);
- ``Settle`` is done once odometry shows the car standing (it moved less than
  :data:`STANDING` metres between two odometry messages);
- ``StopAtRange`` is the direct-code variant: Python reacting to the same range readings,
  with no model in between (the thesis' compiled ROS node): it drives, stops on the first
  reading under ``stop_range``, and is done once the car stands.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping
from typing import Any

from robotale.fame_runtime.bus import Envelope
from robotale.fame_runtime.skills import Cancel, Done, Robot, Skill
from robotale.sim.skills import ODOM, TWIST

RANGE = "sensor_msgs/msg/Range"
STANDING = 0.0005  # metres between two odometry messages: the car stands


def _number(inputs: Mapping[str, Any], robot: Robot, name: str) -> float:
    value = inputs.get(name, robot.variables.get(name))
    return float(value)


def _command(robot: Robot, speed: float) -> None:
    robot.publish("cmd_vel", {"linear": {"x": speed}, "angular": {"z": 0.0}}, TWIST)


def drive(robot: Robot, inputs: Mapping[str, Any], done: Done) -> Cancel | None:
    _command(robot, _number(inputs, robot, "speed"))
    done({})
    return None


def settle(robot: Robot, inputs: Mapping[str, Any], done: Done) -> Cancel:
    return _when_standing(robot, lambda: done({}))


def stop_at_range(robot: Robot, inputs: Mapping[str, Any], done: Done) -> Cancel:
    stop_range = _number(inputs, robot, "stop_range")
    waits: list[Cancel] = []

    def sensed(envelope: Envelope) -> None:
        if waits or envelope.data["range"] >= stop_range:
            return
        _command(robot, 0.0)
        subscription.unsubscribe()
        waits.append(_when_standing(robot, lambda: done({"stopped_at": envelope.data["range"]})))

    def cancel() -> None:
        subscription.unsubscribe()
        for wait in waits:
            wait()

    subscription = robot.subscribe("range", sensed, RANGE)
    _command(robot, _number(inputs, robot, "speed"))
    return cancel


def _when_standing(robot: Robot, then: Callable[[], None]) -> Cancel:
    """Call ``then`` once two odometry messages in a row show the car in one place."""
    last: list[tuple[float, float]] = []

    def moved(envelope: Envelope) -> None:
        position = envelope.data["pose"]["pose"]["position"]
        here = (position["x"], position["y"])
        if last and math.dist(here, last[0]) < STANDING:
            subscription.unsubscribe()
            then()
            return
        last[:] = [here]

    subscription = robot.subscribe("odom", moved, ODOM)
    return subscription.unsubscribe


SKILLS: dict[str, Skill] = {"Drive": drive, "Settle": settle, "StopAtRange": stop_at_range}
