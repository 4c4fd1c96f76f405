"""A rosbag2 recording of live robots: everything robotale can read on the DDS domain, written
as it arrives, by the same recorder that writes a simulated run's bag."""

from __future__ import annotations

import time
from dataclasses import replace
from pathlib import Path
from typing import TextIO

from cyclonedds.builtin import BuiltinDataReader, BuiltinTopicDcpsPublication
from cyclonedds.core import Policy

from robotale.errors import InputError
from robotale.fame_runtime.bus import Envelope
from robotale.fame_runtime.clock import WallClock
from robotale.fame_runtime.dds import DdsBus, type_of
from robotale.fame_runtime.node import STATUS_TOPIC
from robotale.fame_runtime.qos import DEFAULT_QOS
from robotale.fame_runtime.rostypes import known, ros_topic
from robotale.sim.recorder import Recorder

#: seconds between two looks for new publications on the domain
DISCOVERY_POLL = 0.1


class LiveRecording:
    """A rosbag2 of everything robotale can read on the domain, written as it arrives."""

    def __init__(self, path: Path, robots: list[str], offset: float) -> None:
        if path.exists():
            raise InputError(f"{path} exists already: record into a new folder")
        self.clock = WallClock(offset=offset)
        self.bus = DdsBus(self.clock, node="recorder", recorder=True)
        self.recorder = Recorder(path, robots=robots, announced={}, rate=None)
        self.path = path
        self._seen: set[str] = set()
        self._publications = _publication_reader(self.bus)
        self._discover()

    def _discover(self) -> None:
        """Subscribe to each new ROS-typed topic, asking what its publisher offers."""
        for sample in self._publications.take(N=256):
            # a publication that ended comes as a sample without data (no topic, no type)
            if not sample.sample_info.valid_data or sample.type_name is None:
                continue
            msgtype = type_of(sample.type_name)
            topic = ros_topic(sample.topic_name)
            if not sample.topic_name.startswith("rt/") or topic == STATUS_TOPIC:
                continue
            if msgtype is None or not known(msgtype) or (topic, msgtype) in self._seen:
                continue
            self._seen.add((topic, msgtype))
            self.bus.subscribe(topic, self._write, msgtype=msgtype, qos=_asking(sample.qos))
        self.clock.call_later(DISCOVERY_POLL, self._discover)

    def _write(self, envelope: Envelope) -> None:
        self.recorder.tap(envelope)

    def pump(self, seconds: float) -> None:
        self.clock.run(until=self.clock.now() + seconds)

    def close(self, err: TextIO) -> None:
        """Write what is still on its way, then close the bag."""
        quiet_until = time.monotonic() + 0.3
        while time.monotonic() < quiet_until:
            # what the readers hold already, even if Cyclone has not called their listeners
            pending = self.bus.drain() + self.bus.pending
            self.pump(0.05)
            if pending:
                quiet_until = time.monotonic() + 0.3
        self.recorder.close()
        self.bus.close()
        counts = ", ".join(f"{t} {c}" for t, c in sorted(self.recorder.counts.items()) if c)
        print(f"# recorded {self.path}: {counts or 'nothing'}", file=err)


def _publication_reader(bus: DdsBus):
    return BuiltinDataReader(bus.participant, BuiltinTopicDcpsPublication)


def _asking(offered):
    """A reader QoS every publisher offering ``offered`` serves: its reliability and
    durability, everything kept, no deadline or liveliness demands."""
    reliable = isinstance(offered[Policy.Reliability], Policy.Reliability.Reliable)
    latched = offered[Policy.Durability] == Policy.Durability.TransientLocal
    return replace(
        DEFAULT_QOS,
        reliability="reliable" if reliable else "best_effort",
        durability="transient_local" if latched else "volatile",
        history="keep_all",
    )
