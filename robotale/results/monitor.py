"""Watching a live run: each robot's tags stored in Neo4j as they are heard (the live run's log
grows while the run goes on), replayed on the robot's pool, and alerts raised, printed, stored
and published on ``/robotale/alerts``. ``robotale monitor`` watches robots on DDS with it,
``robotale simulate --live`` simulated robots on their in-process bus."""

from __future__ import annotations

import functools
import json
import time
from collections.abc import Callable
from concurrent.futures import Future, ThreadPoolExecutor
from dataclasses import asdict, dataclass, field, replace
from typing import Any, Protocol, TextIO, cast

from neo4j import Driver

from robotale.discovery.online import PoolReplay
from robotale.ekg.columnar import stored_table
from robotale.ekg.growing import GrowingLog
from robotale.ekg.live import Alert, LiveLog, Pose
from robotale.enhancement.overdue import MessageLimits, Overdue, duration_limits
from robotale.errors import InputError
from robotale.fame_runtime.bus import Bus, Envelope
from robotale.fame_runtime.clock import RunningClock
from robotale.fame_runtime.node import KEEP_ALL
from robotale.fame_runtime.qos import DEFAULT_QOS
from robotale.fame_runtime.tags import START, TAG_TYPE, Tag, tag_line, tag_topic
from robotale.results.live import LiveEvents
from robotale.thresholds import LOW_BATTERY_PERCENT

#: where alerts are published, as JSON text in a std_msgs/msg/String
ALERT_TOPIC = "/robotale/alerts"
ALERT_TYPE = "std_msgs/msg/String"
BATTERY_TYPE = "sensor_msgs/msg/BatteryState"
ODOMETRY_TYPE = "nav_msgs/msg/Odometry"
#: what a battery or odometry reader asks for: any writer's samples, reliable or not
BATTERY_QOS = replace(DEFAULT_QOS, reliability="best_effort")
#: seconds between two looks at the robots' silence (and two stores of odometry samples)
TICK = 0.1
#: wall seconds between two appends to the live run's event knowledge graph (wall, not the
#: bus's clock: a simulation running a thousand times faster than the wall would otherwise
#: have its graph rebuilt back to back, each update costing more as the run grows)
BATCH = 1.0
#: odometry samples kept per robot and second, at most (a robot may publish far more)
ODOMETRY_RATE = 10.0


@dataclass(frozen=True)
class Limits:
    """When the monitor alerts: seconds of silence, battery percent, seconds a message may
    take per type, seconds an activity may run (95th percentile of earlier runs)."""

    silence: float = 10.0
    battery: float = LOW_BATTERY_PERCENT
    messages: MessageLimits = field(default_factory=MessageLimits)
    durations: dict[str, float] = field(default_factory=dict)


class WatchedBus(Bus, Protocol):
    """What the monitor needs of a bus: topics, and the clock that delivers them."""

    clock: RunningClock


class Monitor:
    """The robots' tags as they are heard: replayed, printed, their silences watched and
    alerts raised at once from what is held in memory; stored in Neo4j behind that, on
    threads of their own, so a slow store never holds an alert or the reading of DDS back."""

    def __init__(
        self,
        bus: WatchedBus,
        live: LiveLog,
        replays: dict[str, PoolReplay],
        limits: Limits,
        out: TextIO,
        graph: GrowingLog | None = None,
        relay: Bus | None = None,
    ) -> None:
        self.bus, self.live, self.out = bus, live, out
        #: the buses the alerts are published on: the watched one, and ``relay`` (a DDS
        #: domain's, where robots and operators hear a simulated run's alerts)
        self.alert_buses = [bus] if relay is None else [bus, relay]
        #: the live run's event knowledge graph, appended to every BATCH seconds
        self.graph = graph
        #: the run's events as the graph was last given them, made again of its new tags only
        self.graph_events = LiveEvents()
        self.tags: list[Tag] = []
        self.store_live = Writer(self._write_live)
        self.store_graph = Writer(self._write_graph)
        #: what was heard or raised and is not stored yet
        self.unstored: list[Tag] = []
        self.alerts: list[Alert] = []
        self.appended, self.last_append = 0, time.monotonic()
        #: odometry samples not stored yet, and when each robot's next one is kept
        self.poses: list[Pose] = []
        self.pose_due: dict[str, float] = {}
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
            bus.subscribe(
                f"/{robot}/odom",
                functools.partial(self._odometry, robot),
                msgtype=ODOMETRY_TYPE,
                qos=BATTERY_QOS,
            )
        # a DDS writer is made now, so readers match it before the first alert, and kept for
        # late joiners; an in-process bus needs none
        for alerts in self.alert_buses:
            declare = getattr(alerts, "writer", None)
            if declare is not None:
                declare(ALERT_TOPIC, ALERT_TYPE, KEEP_ALL, "monitor")

    def _tag(self, envelope: Envelope) -> None:
        tag: Tag = envelope.data
        if tag.robot not in self.heard:
            return  # a tag published on a robot's topic under another name: not this run's
        self.tags.append(tag)
        self.unstored.append(tag)
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

    def _odometry(self, robot: str, envelope: Envelope) -> None:
        """Keep the sample if the robot's last kept one is 1/ODOMETRY_RATE s older."""
        pose = odometry_pose(robot, envelope)
        if pose.stamp < self.pose_due.get(robot, float("-inf")) - 1e-9:
            return
        self.pose_due[robot] = pose.stamp + 1.0 / ODOMETRY_RATE
        self.poses.append(pose)

    def store(self, *, final: bool = False) -> None:
        """Hand what was heard since the last store to the live log's writer (tags, alerts,
        odometry samples) and, every BATCH seconds (or at the end), the events heard so far
        to the graph's; each writer takes the next batch once it has written the last."""
        if self.store_live.free(final) and (self.unstored or self.alerts or self.poses):
            batch = (self.unstored, self.alerts, self.poses)
            self.unstored, self.alerts, self.poses = [], [], []
            self.store_live.start(batch, final)
        if self.graph is None or not self.store_graph.free(final):
            return
        # the graph gets the tags the live log holds already: a reader that finds the graph
        # finds its tags too (and never takes a run being stored for an ingested log)
        stored, now = self.live.count, time.monotonic()
        if (final or now - self.last_append >= BATCH) and stored > self.appended:
            self.appended, self.last_append = stored, now
            self.store_graph.start(self.tags[:stored], final)

    def _write_live(self, batch: tuple[list[Tag], list[Alert], list[Pose]]) -> None:
        tags, alerts, poses = batch
        self.live.append_tags(tags)
        self.live.alerts(alerts)
        self.live.poses(poses)

    def _write_graph(self, heard: list[Tag]) -> None:
        """The graph given the events of the tags ``heard`` (all so far): made again from
        the earliest activity still open on, the graph told how many first events are as
        they were, so neither makes the whole run again each time."""
        assert self.graph is not None  # only started with a graph
        made = self.graph_events
        events, _, _, kept = made.add(self.live.name, heard[len(made.tags) :])
        self.graph.update(events, same=kept)

    def finish(self) -> None:
        """The watch ended: the last tags, alerts and events stored, the live graph complete."""
        try:
            self.store(final=True)
            if self.graph is not None:
                self.graph.finish()
        finally:
            self.store_live.close()
            self.store_graph.close()

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
        """Printed and published now; stored with the next batch."""
        print(f"# alert {alert.kind} {alert.robot}: {alert.text}", file=self.out, flush=True)
        text = json.dumps(asdict(alert), separators=(",", ":"))
        for alerts in self.alert_buses:
            alerts.publish(
                ALERT_TOPIC, {"data": text}, msgtype=ALERT_TYPE, sender="monitor", qos=KEEP_ALL
            )
        self.alerts.append(alert)

    def pump(self, seconds: float) -> None:
        self.bus.clock.run(until=self.bus.clock.now() + seconds)
        self.watch()
        self.store()


class Writer:
    """One batch at a time written on a thread of its own: what is heard meanwhile waits for
    the next batch, so the batches grow while the store is slow and nothing queues up behind
    it. A failed write's error ends the watch at the next look."""

    def __init__(self, write: Callable[[Any], None]) -> None:
        self.write = write
        # Ctrl-C reaches the watch's own handler, not the write's deferred one
        self.thread = ThreadPoolExecutor(max_workers=1)
        self.writing: Future[None] | None = None

    def free(self, final: bool = False) -> bool:
        """Whether the last batch is written (waiting for it when ``final``)."""
        if self.writing is None:
            return True
        if not (final or self.writing.done()):
            return False
        writing, self.writing = self.writing, None
        writing.result()  # its error, if it failed
        return True

    def start(self, batch: Any, final: bool = False) -> None:
        self.writing = self.thread.submit(self.write, batch)
        if final:
            self.free(final=True)

    def close(self) -> None:
        self.thread.shutdown()


def odometry_pose(robot: str, envelope: Envelope) -> Pose:
    """Where a nav_msgs/msg/Odometry sample puts ``robot``, at the sample's own stamp (its
    arrival when its header has none)."""
    data = envelope.data
    stamp = data.get("header", {}).get("stamp", {})
    seconds = float(stamp.get("sec", 0)) + float(stamp.get("nanosec", 0)) / 1e9
    at = data.get("pose", {}).get("pose", {}).get("position", {})
    return Pose(
        seconds or envelope.stamp,
        robot,
        float(at.get("x", 0.0)),
        float(at.get("y", 0.0)),
        float(at.get("z", 0.0)),
    )


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
                self.messages.begin(tag.msg_id, tag.stamp, self.limits.messages.of(tag.activity))
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
            robot, activity = cast("tuple[str, str]", late.key)
            text = (
                f"{robot}'s {activity!r} running {now - late.stamp:.1f} s, longer than "
                f"{late.limit:.1f} s (the 95th percentile of its earlier durations)"
            )
            alerts.append(Alert(now, "duration", robot, text))
        return alerts


def earlier_durations(driver: Driver, logs: list[str]) -> dict[str, float]:
    """The duration limits of the activities of the stored ``logs`` (earlier runs)."""
    return duration_limits(stored_table(driver, name) for name in logs)


def alert_limits(
    driver: Driver,
    silence: float,
    battery: float,
    message_timeout: list[str] | None,
    durations_from: list[str] | None,
) -> Limits:
    """The limits the options of ``monitor`` and ``simulate --live`` give: ``silence``
    seconds, ``battery`` percent, ``message_timeout`` (``[TYPE=]SECONDS`` texts), the 95th
    percentiles of the activities' durations in the stored logs ``durations_from``."""
    if silence <= 0:
        raise InputError(f"--silence {silence} is not a time: give seconds above 0")
    messages = MessageLimits.parse(message_timeout or [])
    return Limits(silence, battery, messages, earlier_durations(driver, durations_from or []))
