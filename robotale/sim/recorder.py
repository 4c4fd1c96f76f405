"""Recording a run as a rosbag2 (rosbags' writer; sqlite3 by default, MCAP on request).

The recorder taps the bus, so it sees every message when it is published (a dropped delivery
is still in the bag, as ``ros2 bag record`` on the sender's side would have it). It keeps:

- every robot's tags (``/<robot>/tag``, ``robotale_msgs/msg/Tag``);
- odometry and battery (``/<robot>/odom``, ``/<robot>/battery``) at most ``rate`` times a
  second per topic;
- every signal topic (any topic outside a robot's namespace), every error topic of the model
  (``/<robot>/low_battery``), and the robots' event-like topics: take-off, land, blade, LED,
  detections, collisions;
- any other robot topic named in ``extra`` (``range``, ``cmd_vel`` ...), at ``rate``.

With ``rate=None`` it keeps every message of every topic (a live run's recording: what
arrives is what the robots really sent).

The connections of the topics the mission is known to use are announced when the bag opens;
others are added when their first message arrives. Message timestamps are simulated time. Each
topic offers rclcpp's default QoS, and the metadata is written as the chosen ROS 2
distribution's ``ros2 bag`` writes it (:mod:`robotale.sim.bagmeta`; Humble's by default, which
every supported distribution reads).
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping
from pathlib import Path

from rosbags.rosbag2 import StoragePlugin, Writer

from robotale.errors import InputError
from robotale.fame_runtime.bus import Envelope
from robotale.fame_runtime.tags import TAG_TYPE
from robotale.sim import bagmeta, messages
from robotale.sim.robots import BATTERY, ODOM

STORAGES = {"sqlite3": StoragePlugin.SQLITE3, "mcap": StoragePlugin.MCAP}
THROTTLED = frozenset({"odom", "battery"})
EVENT_TOPICS = frozenset({"tag", "takeoff", "land", "blade_force", "led", "detection", "collision"})
KEEP, THROTTLE, SKIP = "keep", "throttle", "skip"


class Recorder:
    def __init__(
        self,
        path: Path,
        *,
        robots: Iterable[str],
        announced: Mapping[str, str],
        storage: str = "sqlite3",
        rate: float | None = 2.0,
        errors: Iterable[str] = (),
        extra: Iterable[str] = (),
        distro: str = bagmeta.DEFAULT_DISTRO,
    ) -> None:
        if storage not in STORAGES:
            raise InputError(f"storage {storage!r} is not one of {', '.join(STORAGES)}")
        if distro not in bagmeta.VERSIONS:
            raise InputError(f"distro {distro!r} is not one of {', '.join(bagmeta.VERSIONS)}")
        self.path, self.distro = Path(path), distro
        self.robots = frozenset(robots)
        self.period = 1.0 / rate if rate else 0.0
        self.keep_all = rate is None
        self.errors = frozenset(errors)
        self.extra = frozenset(extra)
        self._policies: dict[str, str] = {}
        self.counts: dict[str, int] = {}
        self.types: dict[str, str] = {}
        self._due: dict[str, float] = {}
        self._connections: dict[tuple[str, str], object] = {}
        self._writer = Writer(
            path, version=bagmeta.writer_version(distro), storage_plugin=STORAGES[storage]
        )
        self._writer.open()
        for robot in sorted(self.robots):
            self._connect(f"/{robot}/tag", TAG_TYPE)
            self._connect(f"/{robot}/odom", ODOM)
            self._connect(f"/{robot}/battery", BATTERY)
        for topic, msgtype in sorted(announced.items()):
            self._connect(topic, msgtype)

    def _connect(self, topic: str, msgtype: str):
        key = (topic, msgtype)
        if key not in self._connections:
            self._connections[key] = self._writer.add_connection(
                topic,
                msgtype,
                typestore=messages.typestore(),
                offered_qos_profiles=[bagmeta.DEFAULT_QOS],
            )
            self.types.setdefault(topic, msgtype)
            self.counts.setdefault(topic, 0)
        return self._connections[key]

    def tap(self, envelope: Envelope) -> None:
        """Write ``envelope`` if the recording keeps its topic (a bus tap)."""
        topic = envelope.topic
        policy = self._policies.get(topic) or self._policies.setdefault(topic, self._policy(topic))
        if policy == SKIP:
            return
        if policy == THROTTLE:
            if envelope.stamp < self._due.get(topic, float("-inf")) - 1e-9:
                return
            self._due[topic] = envelope.stamp + self.period
        data = messages.serialize(envelope.msgtype, envelope.data, topic)
        connection = self._connect(topic, envelope.msgtype)
        self._writer.write(connection, round(envelope.stamp * 1e9), data)
        self.counts[topic] += 1

    def _policy(self, topic: str) -> str:
        if self.keep_all:
            return KEEP
        parts = topic.strip("/").split("/")
        if len(parts) < 2 or parts[0] not in self.robots:
            return KEEP  # a signal
        leaf = "/".join(parts[1:])
        if leaf in EVENT_TOPICS or leaf in self.errors:
            return KEEP
        if leaf in THROTTLED or leaf in self.extra:
            return THROTTLE
        return SKIP

    def close(self) -> None:
        self._writer.close()
        bagmeta.for_distro(self.path, self.distro)

    def topics(self) -> dict[str, dict[str, object]]:
        """Each recorded topic's type and message count (what the bag announces)."""
        return {t: {"type": self.types[t], "count": self.counts[t]} for t in sorted(self.types)}
