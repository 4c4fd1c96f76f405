"""``robotale monitor``: watch live robots over DDS, storing each tag in Neo4j as it arrives
(the live run's log grows while the run goes on) and raising alerts printed, stored and
published on ``/robotale/alerts``."""

from __future__ import annotations

import functools
import json
import sys
import threading
import time
from dataclasses import asdict, replace
from pathlib import Path
from typing import TextIO

from robotale.discovery.online import PoolReplay, pool_replays
from robotale.ekg.connection import session_driver
from robotale.ekg.live import Alert, LiveLog
from robotale.errors import InputError
from robotale.fame_runtime.bus import Envelope
from robotale.fame_runtime.clock import WallClock
from robotale.fame_runtime.dds import DdsBus
from robotale.fame_runtime.launch import robot_list
from robotale.fame_runtime.node import KEEP_ALL
from robotale.fame_runtime.processes import interrupts
from robotale.fame_runtime.qos import DEFAULT_QOS
from robotale.fame_runtime.tags import TAG_TYPE, Tag, tag_line, tag_topic
from robotale.thresholds import LOW_BATTERY_PERCENT

#: where alerts are published, as JSON text in a std_msgs/msg/String
ALERT_TOPIC = "/robotale/alerts"
ALERT_TYPE = "std_msgs/msg/String"
BATTERY_TYPE = "sensor_msgs/msg/BatteryState"
#: what a battery reader asks for: any writer's samples, reliable or not
BATTERY_QOS = replace(DEFAULT_QOS, reliability="best_effort")
#: seconds between two looks at the robots' silence
TICK = 0.1


class Monitor:
    """The robots' tags as they are heard: stored, printed, and their silences watched."""

    def __init__(
        self,
        bus: DdsBus,
        live: LiveLog,
        replays: dict[str, PoolReplay],
        silence: float,
        battery: float,
        out: TextIO,
    ) -> None:
        self.bus, self.live, self.silence, self.out = bus, live, silence, out
        self.battery = battery
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


def monitor_command(
    model: Path,
    *,
    log: str,
    robots: str | None = None,
    silence: float = 10.0,
    battery: float = LOW_BATTERY_PERCENT,
    duration: float | None = None,
    out: TextIO | None = None,
    err: TextIO | None = None,
) -> int:
    """Watch the mission's robots until Ctrl-C or ``duration`` seconds, storing their tags
    as the live log ``log`` and alerting when one is silent longer than ``silence`` or its
    battery (``/<robot>/battery``) is below ``battery`` percent."""
    out, err = out or sys.stdout, err or sys.stderr
    if silence <= 0:
        raise InputError(f"--silence {silence} is not a time: give seconds above 0")
    replays = pool_replays(model, robot_list(robots))
    deadline = time.monotonic() + duration if duration is not None else float("inf")
    stopped = threading.Event()
    with session_driver() as driver:
        bus = DdsBus(WallClock(offset=0.0), node="monitor")
        try:
            monitor = Monitor(bus, LiveLog(driver, log), replays, silence, battery, out)
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
