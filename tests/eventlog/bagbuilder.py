"""Real rosbag2 recordings written in the tests with the rosbags writer.

:class:`BagBuilder` collects tags, odometry and battery samples with known values and writes
them as a rosbag2 directory (sqlite3 or MCAP), with the robotale Tag type and the standard
nav_msgs/sensor_msgs types embedded as any ROS 2 Iron+ recorder does.
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pandas as pd
from rosbags.rosbag2 import StoragePlugin, Writer
from rosbags.typesys import Stores, get_types_from_msg, get_typestore

from robotale.fame_runtime.tags import TAG_TYPE, register_tag_type

#: time zero of the test recordings
EPOCH = pd.Timestamp("2023-05-16T10:00:00Z")


def at(seconds: float) -> pd.Timestamp:
    """The timestamp ``seconds`` after :data:`EPOCH`."""
    return EPOCH + pd.Timedelta(round(seconds * 1e9), unit="ns")


def nanos(seconds: float) -> int:
    return EPOCH.value + round(seconds * 1e9)


class BagBuilder:
    """Messages to write, by topic; ``write`` records them in time order."""

    def __init__(self) -> None:
        self.typestore = get_typestore(Stores.ROS2_HUMBLE)
        register_tag_type(self.typestore)
        self.messages: list[tuple[int, int, str, str, object]] = []
        self.extra_types: dict[str, str] = {}

    def _add(self, seconds: float, topic: str, msgtype: str, message: object, recorded=None):
        when = nanos(seconds if recorded is None else recorded)
        self.messages.append((when, len(self.messages), topic, msgtype, message))
        return self

    def _time(self, seconds: float):
        t = nanos(seconds)
        return self.typestore.types["builtin_interfaces/msg/Time"](
            sec=t // 1_000_000_000, nanosec=t % 1_000_000_000
        )

    def _header(self, seconds: float, frame: str = "map"):
        header = self.typestore.types["std_msgs/msg/Header"]
        return header(stamp=self._time(seconds), frame_id=frame)

    def tag(
        self,
        seconds,
        robot,
        activity,
        lifecycle,
        msg_id="",
        msg_role="",
        payload="",
        *,
        topic=None,
        stamp_robot=True,
        recorded=None,
    ):
        Tag = self.typestore.types[TAG_TYPE]
        message = Tag(
            stamp=self._time(seconds),
            robot=robot if stamp_robot else "",
            activity=activity,
            lifecycle=lifecycle,
            msg_id=msg_id,
            msg_role=msg_role,
            payload=payload,
        )
        return self._add(seconds, topic or f"/{robot}/tag", TAG_TYPE, message, recorded)

    def odom(self, seconds, robot, x, y, z, *, topic=None, frame="odom"):
        t = self.typestore.types
        pose = t["geometry_msgs/msg/Pose"](
            position=t["geometry_msgs/msg/Point"](x=float(x), y=float(y), z=float(z)),
            orientation=t["geometry_msgs/msg/Quaternion"](x=0.0, y=0.0, z=0.0, w=1.0),
        )
        vector = t["geometry_msgs/msg/Vector3"](x=0.0, y=0.0, z=0.0)
        message = t["nav_msgs/msg/Odometry"](
            header=self._header(seconds, frame),
            child_frame_id="base_link",
            pose=t["geometry_msgs/msg/PoseWithCovariance"](pose=pose, covariance=np.zeros(36)),
            twist=t["geometry_msgs/msg/TwistWithCovariance"](
                twist=t["geometry_msgs/msg/Twist"](linear=vector, angular=vector),
                covariance=np.zeros(36),
            ),
        )
        return self._add(seconds, topic or f"/{robot}/odom", "nav_msgs/msg/Odometry", message)

    def battery(self, seconds, robot, fraction, *, topic=None):
        msgtype = "sensor_msgs/msg/BatteryState"
        empty = np.zeros(0, dtype=np.float32)
        message = self.typestore.types[msgtype](
            header=self._header(seconds),
            voltage=12.0,
            temperature=20.0,
            current=-1.0,
            charge=1.0,
            capacity=2.0,
            design_capacity=2.0,
            percentage=float(fraction),
            power_supply_status=2,
            power_supply_health=1,
            power_supply_technology=3,
            present=True,
            cell_voltage=empty,
            cell_temperature=empty,
            location="",
            serial_number="",
        )
        return self._add(seconds, topic or f"/{robot}/battery", msgtype, message)

    def custom(self, seconds, topic, msgtype, definition, **fields):
        """A message of a type defined here (as a real robot's own package would)."""
        if msgtype not in self.typestore.fielddefs:
            self.typestore.register(get_types_from_msg(definition, msgtype))
            self.extra_types[msgtype] = definition
        return self._add(seconds, topic, msgtype, self.typestore.types[msgtype](**fields))

    def write(self, path: Path, *, storage: str = "sqlite3", manifest: dict | None = None) -> Path:
        plugin = StoragePlugin.MCAP if storage == "mcap" else StoragePlugin.SQLITE3
        with Writer(path, version=9, storage_plugin=plugin) as writer:
            connections = {}
            for when, _, topic, msgtype, message in sorted(self.messages, key=lambda m: m[:2]):
                if topic not in connections:
                    connections[topic] = writer.add_connection(
                        topic, msgtype, typestore=self.typestore
                    )
                data = self.typestore.serialize_cdr(message, msgtype)
                writer.write(connections[topic], when, bytes(data))
        if manifest is not None:
            (path / "robotale-run.json").write_text(json.dumps(manifest))
        return path


def agri_like(builder, x0: float = 0.0):
    """A drone and a tractor: odometry, battery and tags with values easy to compute by hand.

    drone: odom every 1 s (x = x0 + t, y = 2t, z = 1.5), battery every 2 s (1 - t/100);
    tractor_1: odom every 0.5 s (x = x0 + 10 + t), battery at 0, 5, 10 s (0.9, 0.8, 0.7).
    """
    b = builder()
    for t in range(11):
        b.odom(t, "drone", x0 + t, 2 * t, 1.5)
    for t in range(0, 11, 2):
        b.battery(t, "drone", 1 - t / 100)
    for k in range(21):
        b.odom(k / 2, "tractor_1", x0 + 10 + k / 2, 0, 0)
    for t, fraction in ((0, 0.9), (5, 0.8), (10, 0.7)):
        b.battery(t, "tractor_1", fraction)
    b.tag(0.5, "drone", "take_off", "start").tag(2.5, "drone", "take_off", "complete")
    b.tag(2.5, "drone", "explore", "start").tag(5.2, "drone", "explore", "complete")
    b.tag(5.2, "drone", "weed_position!", "start", "m1", "send", '{"x": 6}')
    b.tag(5.2, "drone", "weed_position!", "complete", "m1", "send", '{"x": 6}')
    b.tag(5.3, "tractor_1", "weed_position?", "start", "m1", "receive", '{"x": 6}')
    b.tag(5.3, "tractor_1", "weed_position?", "complete", "m1", "receive", '{"x": 6}')
    b.tag(5.4, "tractor_1", "move", "start").tag(7.4, "tractor_1", "move", "complete")
    b.tag(9.5, "drone", "land", "start").tag(10.5, "drone", "land", "complete")
    return b
