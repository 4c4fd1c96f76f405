"""``robotale monitor``: watch live robots over DDS, storing each tag in Neo4j as it arrives
(the live run's log grows while the run goes on) and raising alerts printed, stored and
published on ``/robotale/alerts``."""

from __future__ import annotations

import functools
import json
import sys
import threading
import time
from dataclasses import asdict, dataclass, field, replace
from pathlib import Path
from typing import TextIO

from neo4j import Driver

from robotale.discovery.online import PoolReplay, pool_replays
from robotale.ekg.columnar import stored_table
from robotale.ekg.connection import session_driver
from robotale.ekg.live import Alert, LiveLog
from robotale.enhancement.overdue import MessageLimits, Overdue, duration_limits
from robotale.errors import InputError
from robotale.fame_runtime.bus import Envelope
from robotale.fame_runtime.clock import WallClock
from robotale.fame_runtime.dds import DdsBus
from robotale.fame_runtime.launch import robot_list
from robotale.fame_runtime.node import KEEP_ALL
from robotale.fame_runtime.processes import interrupts
from robotale.fame_runtime.qos import DEFAULT_QOS
from robotale.fame_runtime.tags import START, TAG_TYPE, Tag, tag_line, tag_topic
from robotale.thresholds import LOW_BATTERY_PERCENT

#: where alerts are published, as JSON text in a std_msgs/msg/String
ALERT_TOPIC = "/robotale/alerts"
ALERT_TYPE = "std_msgs/msg/String"
BATTERY_TYPE = "sensor_msgs/msg/BatteryState"
#: what a battery reader asks for: any writer's samples, reliable or not
BATTERY_QOS = replace(DEFAULT_QOS, reliability="best_effort")
#: seconds between two looks at the robots' silence
TICK = 0.1


@dataclass(frozen=True)
class Limits:
    """When the monitor alerts: seconds of silence, battery percent, seconds a message may
    take per type, seconds an activity may run (95th percentile of earlier runs)."""

    silence: float = 10.0
    battery: float = LOW_BATTERY_PERCENT
    messages: MessageLimits = field(default_factory=MessageLimits)
    durations: dict[str, float] = field(default_factory=dict)


class Monitor:
    """The robots' tags as they are heard: stored, printed, and their silences watched."""

    def __init__(
        self,
        bus: DdsBus,
        live: LiveLog,
        replays: dict[str, PoolReplay],
        limits: Limits,
        out: TextIO,
    ) -> None:
        self.bus, self.live, self.out = bus, live, out
        self.silence, self.battery, self.limits = limits.silence, limits.battery, limits
        self.timing = Timing(limits)
        self.low: set[str] = set()
        self.replays = replays
        robots = list(replays)
        self.begin = bus.clock.now()
        self.heard = dict.fromkeys(robots, self.begin)
        self.silent: set[str] = set()
        for robot in robots:
            bus.subscribe(tag_topic(robot), self._tag, msgtype=TAG_TYPE, qos=KEEP_ALL)
            bus.subscribe(
                f"/{robot}/battery",
                functools.partial(self._battery, robot),
                msgtype=BATTERY_TYPE,
                qos=BATTERY_QOS,
            )
        # written now, so readers match it before the first alert; kept for late joiners
        bus.writer(ALERT_TOPIC, ALERT_TYPE, KEEP_ALL, "monitor")

    def _tag(self, envelope: Envelope) -> None:
        tag: Tag = envelope.data
        if tag.robot not in self.heard:
            return  # a tag published on a robot's topic under another name: not this run's
        self.live.append(tag)
        self.heard[tag.robot] = self.bus.clock.now()
        self.silent.discard(tag.robot)
        print(tag_line(tag, self.begin), file=self.out, flush=True)
        self.timing.heard(tag)
        replay = self.replays[tag.robot]
        if not replay.allows(tag):
            text = (
                f"{tag.robot} started {tag.activity!r} (tag stamped {tag.stamp:.3f}) where "
                f"its pool {replay.pool} does not allow it"
            )
            self.raise_alert(Alert(self.bus.clock.now(), "deviation", tag.robot, text))

    def _battery(self, robot: str, envelope: Envelope) -> None:
        """Alert once when the charge falls below the threshold (again after it rose)."""
        percent = 100.0 * float(envelope.data.get("percentage", 0.0))
        if percent >= self.battery:
            self.low.discard(robot)
        elif robot not in self.low:
            self.low.add(robot)
            text = f"{robot}'s battery at {percent:.1f} %, below {self.battery:g} %"
            self.raise_alert(Alert(self.bus.clock.now(), "battery", robot, text))

    def watch(self) -> None:
        """Alert once for each robot silent longer than the limit (again after it spoke)."""
        now = self.bus.clock.now()
        for robot, heard in self.heard.items():
            if robot not in self.silent and now - heard > self.silence:
                self.silent.add(robot)
                self.raise_alert(
                    Alert(now, "silence", robot, f"{robot} silent for {now - heard:.1f} s")
                )
        for alert in self.timing.due(now):
            self.raise_alert(alert)

    def raise_alert(self, alert: Alert) -> None:
        print(f"# alert {alert.kind} {alert.robot}: {alert.text}", file=self.out, flush=True)
        self.live.alert(alert)
        text = json.dumps(asdict(alert), separators=(",", ":"))
        self.bus.publish(
            ALERT_TOPIC, {"data": text}, msgtype=ALERT_TYPE, sender="monitor", qos=KEEP_ALL
        )

    def pump(self, seconds: float) -> None:
        self.bus.clock.run(until=self.bus.clock.now() + seconds)
        self.watch()


class Timing:
    """The messages sent and not yet received, and the activities running, each alerted
    once when it takes longer than its limit."""

    def __init__(self, limits: Limits) -> None:
        self.limits = limits
        self.messages, self.running = Overdue(), Overdue()
        #: send tags carry the message's type (their label) and sender, by message id
        self.sends: dict[str, Tag] = {}
        self.received: set[str] = set()

    def heard(self, tag: Tag) -> None:
        if tag.msg_id and tag.msg_role == "receive":
            self.received.add(tag.msg_id)
            self.messages.end(tag.msg_id)
        elif tag.msg_id and tag.msg_role == "send" and tag.msg_id not in self.sends:
            self.sends[tag.msg_id] = tag
            if tag.msg_id not in self.received:  # a receive heard before its send
                limit = self.limits.messages.of(tag.activity)
                self.messages.begin(tag.msg_id, tag.stamp, limit)
        limit = self.limits.durations.get(tag.activity)
        if limit is None:
            return
        if tag.lifecycle == START:
            self.running.begin((tag.robot, tag.activity), tag.stamp, limit)
        else:  # completed, aborted: over
            self.running.end((tag.robot, tag.activity))

    def due(self, now: float) -> list[Alert]:
        alerts = []
        for late in self.messages.due(now):
            send = self.sends[str(late.key)]
            text = (
                f"message {late.key} ({send.activity!r}) sent by {send.robot} at "
                f"{late.stamp:.3f} not received within {late.limit:g} s"
            )
            alerts.append(Alert(now, "message", send.robot, text))
        for late in self.running.due(now):
            robot, activity = late.key  # type: ignore[misc]
            text = (
                f"{robot}'s {activity!r} running {now - late.stamp:.1f} s, longer than "
                f"{late.limit:.1f} s (the 95th percentile of its earlier durations)"
            )
            alerts.append(Alert(now, "duration", robot, text))
        return alerts


def earlier_durations(driver: Driver, logs: list[str]) -> dict[str, float]:
    """The duration limits of the activities of the stored ``logs`` (earlier runs)."""
    return duration_limits(stored_table(driver, name) for name in logs)


def monitor_command(
    model: Path,
    *,
    log: str,
    robots: str | None = None,
    silence: float = 10.0,
    battery: float = LOW_BATTERY_PERCENT,
    message_timeout: list[str] | None = None,
    durations_from: list[str] | None = None,
    duration: float | None = None,
    out: TextIO | None = None,
    err: TextIO | None = None,
) -> int:
    """Watch the mission's robots until Ctrl-C or ``duration`` seconds, storing their tags
    as the live log ``log`` and alerting when one is silent longer than ``silence`` or its
    battery (``/<robot>/battery``) is below ``battery`` percent, a message is not received
    within its ``message_timeout`` (``[TYPE=]SECONDS`` texts) or an activity runs longer than
    the 95th percentile of its durations in the stored logs ``durations_from``."""
    out, err = out or sys.stdout, err or sys.stderr
    if silence <= 0:
        raise InputError(f"--silence {silence} is not a time: give seconds above 0")
    messages = MessageLimits.parse(message_timeout or [])
    replays = pool_replays(model, robot_list(robots))
    deadline = time.monotonic() + duration if duration is not None else float("inf")
    stopped = threading.Event()
    with session_driver() as driver:
        limits = Limits(silence, battery, messages, earlier_durations(driver, durations_from or []))
        bus = DdsBus(WallClock(offset=0.0), node="monitor")
        try:
            monitor = Monitor(bus, LiveLog(driver, log), replays, limits, out)
            # Ctrl-C or SIGTERM ends the watch between two tags, never inside a store
            with interrupts(stopped.set):
                print(
                    f"# monitoring {', '.join(replays)} as {log} (Ctrl-C stops)",
                    file=err,
                    flush=True,
                )
                while time.monotonic() < deadline and not stopped.is_set():
                    monitor.pump(min(TICK, max(0.0, deadline - time.monotonic())))
                bus.drain()
                monitor.pump(TICK)
        finally:
            bus.close()
    print(f"# {log}: {monitor.live.count} tags stored", file=err)
    return 0
