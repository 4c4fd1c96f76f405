"""What a mission needs from the simulated robots, and what a world's robots lack of it.

A FAME model reaches its robots in two ways robotale can see before anything runs: the
topics and services its JavaScript scripts name (``node.createSubscription(type, "odom")``,
``createPublisher``, ``createClient``), and the signals it catches but never throws itself
(``weed_found``, which the thesis' drone publishes from its camera). Each is compared with
the topics the world's robots publish, obey and serve (:func:`provided`), so a model that
needs ``/tractor_1/laser`` from a world without it is named in one list before a run starts.
"""

from __future__ import annotations

import re
from collections.abc import Iterable
from dataclasses import dataclass

from robotale.errors import ModelError
from robotale.fame_runtime.kinds import THROWING, EventKind, Kind
from robotale.fame_runtime.labels import catches, signal_topic
from robotale.fame_runtime.library import Library, resolve_call
from robotale.fame_runtime.model import JAVASCRIPT, Definitions, Process
from robotale.fame_runtime.splitter import split
from robotale.sim.robots import BATTERY, COLOR, EMPTY, FLOAT64, ODOM, TELLO_ACTION, TWIST
from robotale.sim.sensors import DETECTION, RANGE
from robotale.sim.worldspec import RobotSpec, World

_CALL = re.compile(
    r"\b(?P<kind>createSubscription|createPublisher|createClient)\s*\(\s*"
    r"(?P<q1>[\"'])(?P<type>[^\"']+)(?P=q1)\s*,\s*(?P<q2>[\"'])(?P<topic>[^\"']+)(?P=q2)"
)
#: what a script does with a topic -> what the robot must do with it
_ROLE = {"createSubscription": "publish", "createPublisher": "obey", "createClient": "serve"}


@dataclass(frozen=True, order=True)
class Need:
    """``robot`` must ``role`` (publish | obey | serve) ``topic`` of ``msgtype``; ``by``
    names the element whose script or event needs it."""

    robot: str
    role: str
    topic: str
    msgtype: str
    by: str

    def describe(self) -> str:
        what = {"publish": "publishes", "obey": "subscribes to", "serve": "serves"}[self.role]
        return f"{self.by} needs a robot that {what} {self.topic} ({self.msgtype}) for {self.robot}"


def provided(name: str, spec: RobotSpec) -> dict[tuple[str, str], str]:
    """``{(role, topic): msgtype}`` of what one simulated robot publishes, obeys and serves."""
    own = {
        ("publish", "odom"): ODOM,
        ("publish", "battery"): BATTERY,
        ("publish", "low_battery"): EMPTY,
        ("obey", "cmd_vel"): TWIST,
    }
    if spec.range is not None:
        own[("publish", "range")] = RANGE
    if (spec.range and spec.range.detects) or spec.camera is not None:
        own[("publish", "detection")] = DETECTION
    if spec.kind == "drone":
        own.update({("obey", "takeoff"): EMPTY, ("obey", "land"): EMPTY})
        own[("serve", "tello_action")] = TELLO_ACTION
    if spec.blade:
        own[("obey", "blade_force")] = FLOAT64
    if spec.led:
        own[("obey", "led")] = COLOR
    found = {(role, f"/{name}/{topic}"): msgtype for (role, topic), msgtype in own.items()}
    if spec.camera is not None and spec.camera.signal:
        found[("publish", f"/{spec.camera.signal}")] = "geometry_msgs/msg/Vector3"
    return found


def lacks(definitions: Definitions, world: World, library: Library | None = None) -> list[str]:
    """Every need of the model the world's robots do not meet, one sentence each."""
    specs = {name: spec for spec in world.robots for name in spec.names()}
    offered: dict[tuple[str, str], str] = {}
    for name, spec in specs.items():
        offered.update(provided(name, spec))
    missing = []
    for need in sorted(set(needs(definitions, list(specs), library))):
        msgtype = offered.get((need.role, need.topic))
        if msgtype is None:
            missing.append(need.describe())
        elif msgtype != need.msgtype:
            missing.append(f"{need.describe()}, but the simulated robot's is {msgtype}")
    return missing


def needs(
    definitions: Definitions, robots: list[str], library: Library | None = None
) -> Iterable[Need]:
    """What the model's scripts and uncaught signals need, per robot of ``robots``."""
    # a building block's throw counts (REX's Detect throws DINGO's target_found)
    thrown = {
        signal_topic(node)
        for _, pool in definitions.pools()
        for process in _with_blocks(pool, library)
        for node in process.walk()
        if node.event_kind == EventKind.SIGNAL and node.kind in THROWING
    }
    try:
        assignments = split(definitions, robots)
    except ModelError:  # a building block's own pool: its default robot (Tractor_1: tractor_1)
        assignments = split(definitions)
    for assignment in assignments:
        for process in _with_blocks(assignment.process, library):
            for node in process.walk():
                yield from _script_needs(node, assignment.robot)
                topic = signal_topic(node) if node.event_kind == EventKind.SIGNAL else ""
                if topic and catches(node) and topic not in thrown:
                    msgtype = node.message.msgtype if node.message else "std_msgs/msg/Empty"
                    by = f"{node.kind} {node.describe()}"
                    yield Need(assignment.robot, "publish", topic, msgtype, by)


def _script_needs(node, robot: str) -> Iterable[Need]:
    script = node.script
    if script is None or script.language != JAVASCRIPT:
        return
    for match in _CALL.finditer(script.text):
        topic = match.group("topic")
        topic = topic if topic.startswith("/") else f"/{robot}/{topic}"
        role = _ROLE[match.group("kind")]
        yield Need(robot, role, topic, match.group("type"), f"script task {node.describe()}")


def _with_blocks(process: Process, library: Library | None) -> list[Process]:
    """The process and every process it calls, transitively (each once)."""
    found: dict[int, Process] = {}
    waiting = [process]
    while waiting:
        current = waiting.pop()
        if id(current) in found:
            continue
        found[id(current)] = current
        for node in current.walk():
            if node.kind == Kind.CALL_ACTIVITY and node.called_element:
                called = resolve_call(node.called_element, current, library)
                if called is not None:
                    waiting.append(called)
    return list(found.values())
