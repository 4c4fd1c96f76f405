"""One robot's engine as its own process on DDS (a FAME node, thesis 5.1).

A :class:`Node` runs the process its robot gets from the collaboration on a
:class:`~robotale.fame_runtime.dds.DdsBus` and the wall clock. Its tags go out on
``/<robot>/tag`` (reliable, transient local, every tag kept: a recorder that joins late
still gets them all). Before its robot starts it declares a DDS writer or reader for every
signal its pool throws or catches and waits until the other robots of the mission are up and
those endpoints are matched, so a signal thrown at once is not lost to discovery; when a
recorder is on the domain (``robotale record``, ``fame run --record``) it also waits until
the recorder reads every topic the robot writes, so the bag has the first message too.

Robots say how they are on ``/robotale/status``; the mission is over for a node when every
robot has been idle (no instance running, no timer armed, nothing in flight) for ``settle``
seconds.
"""

from __future__ import annotations

import time
from collections.abc import Callable, Collection, Iterable, Mapping
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Any

from robotale.errors import InputError
from robotale.fame_runtime.check import Endpoint, endpoints
from robotale.fame_runtime.dds import DdsBus, Recorders
from robotale.fame_runtime.engine import Engine
from robotale.fame_runtime.library import Library
from robotale.fame_runtime.model import Definitions
from robotale.fame_runtime.qos import DEFAULT_QOS, pair_problems
from robotale.fame_runtime.rostypes import STATUS_TYPE, to_data
from robotale.fame_runtime.skills import Skill
from robotale.fame_runtime.splitter import split
from robotale.fame_runtime.tags import TAG_TYPE, Tag, TagSink, tag_topic

STATUS_TOPIC = "/robotale/status"
#: tags and statuses: every one kept for readers that join late (a recorder, a slow robot)
KEEP_ALL = replace(DEFAULT_QOS, durability="transient_local", history="keep_all")
#: seconds every robot must have been idle before a node calls the mission over
SETTLE = 0.5
#: seconds between two looks at what the other robots said
POLL = 0.05


@dataclass(frozen=True, slots=True)
class Status:
    robot: str
    ready: bool
    busy: bool
    timer: bool
    completed: int
    where: str


class Node:
    """``robot``'s engine on ``bus`` (a DdsBus on a WallClock). With ``wait_for_recorder``
    the robot also waits for a reader of its tags before it starts."""

    def __init__(
        self,
        definitions: Definitions,
        robot: str,
        *,
        bus: DdsBus,
        robots: Iterable[str] | None = None,
        skills: Mapping[str, Skill] | None = None,
        library: Library | str | Path | None = None,
        variables: Mapping[str, Any] | None = None,
        tag_sink: TagSink | None = None,
        settle: float = SETTLE,
        wait_for_recorder: bool = False,
    ) -> None:
        assignments = split(definitions, robots)
        mine = [a for a in assignments if a.robot == robot]
        if not mine:
            bound = ", ".join(a.robot for a in assignments)
            raise InputError(f"robot {robot!r} is not in the mission (its robots: {bound})")
        self.assignment = mine[0]
        self.robots = [a.robot for a in assignments]
        self.bus, self.clock = bus, bus.clock
        self.settle = settle
        self._extra_sink = tag_sink
        if library is not None and not isinstance(library, Library):
            library = Library(library)
        self.engine = Engine(
            self.assignment.process,
            robot=robot,
            robot_type=self.assignment.robot_type,
            bus=bus,
            clock=self.clock,
            skills=skills,
            tag_sink=self._tag,
            library=library,
            variables=variables,
        )
        self._declare(definitions, skills or {}, library)
        if wait_for_recorder:  # its tags must not end with the process before being recorded
            tags = self.bus.writer(tag_topic(robot), TAG_TYPE, KEEP_ALL, robot)
            self.peered.append((tag_topic(robot), tags.get_publication_matched_status))
        self.statuses: dict[str, Status] = {}
        self._said: Status | None = None
        self._quiet_since: float | None = None
        self.interrupted = False
        self._status_reader = bus.raw_reader(STATUS_TOPIC, STATUS_TYPE, KEEP_ALL)
        self._recorders = Recorders(bus)

    @property
    def robot(self) -> str:
        return self.assignment.robot

    def _declare(
        self, definitions: Definitions, skills: Collection[str], library: Library | None
    ) -> None:
        """Writers and readers for every signal of this robot's pool, and which of them
        must be matched before the robot starts (those another pool uses too)."""
        publishers, subscribers = endpoints(definitions, skills=skills, library=library)
        pool = self.assignment.pool.name
        self.peered: list[tuple[str, Any]] = []
        for topic, mine in publishers.items():
            for endpoint in (e for e in mine if e.pool == pool):
                writer = self.bus.writer(topic, endpoint.msgtype, endpoint.qos, self.robot)
                if any(_talk(endpoint, e) for e in subscribers.get(topic, ()) if e.pool != pool):
                    self.peered.append((topic, writer.get_publication_matched_status))
        for topic, mine in subscribers.items():
            for endpoint in (e for e in mine if e.pool == pool):
                reader = self.bus.reader(topic, endpoint.msgtype, endpoint.qos).reader
                if any(_talk(e, endpoint) for e in publishers.get(topic, ()) if e.pool != pool):
                    self.peered.append((topic, reader.get_subscription_matched_status))
        self.bus.writer(tag_topic(self.robot), TAG_TYPE, KEEP_ALL, self.robot)

    def _tag(self, tag: Tag) -> None:
        self.bus.publish(
            tag_topic(tag.robot), tag, msgtype=TAG_TYPE, sender=tag.robot, qos=KEEP_ALL
        )
        if self._extra_sink is not None:
            self._extra_sink(tag)

    # -- the run -------------------------------------------------------------------------------

    def run(self, *, until: float, wait: float = 30.0, warn: Callable[[str], None]) -> float:
        """Start the robot once the mission is up, run until the mission is over, ``until``
        (absolute time) or an interrupt; returns the time reached."""
        self.engine.start()  # arms the start events; the first instance runs on the clock
        self._say(ready=True)
        self._meet(min(wait, max(0.0, until - self.clock.now())), warn)
        self._poll()
        return self.clock.run(until=until, stop_when=self._over)

    def _meet(self, wait: float, warn: Callable[[str], None]) -> None:
        """Wait until every robot said it is ready and the shared topics are matched."""
        deadline = time.monotonic() + wait
        while True:  # looks at least once, even with no time to wait
            self._take_statuses()
            missing = [r for r in self.robots if r not in self.statuses]
            lonely = sorted({t for t, status in self.peered if not status().current_count})
            unrecorded = self._unrecorded()
            if (not missing and not lonely and not unrecorded) or self.interrupted:
                return
            if time.monotonic() >= deadline:
                break
            time.sleep(0.01)
        if missing:
            warn(f"{self.robot} starts without {', '.join(missing)} (not up after {wait:g} s)")
        if lonely:
            warn(f"{self.robot} starts with no peer yet on {', '.join(lonely)}")
        if unrecorded:
            warn(f"{self.robot} starts before the recorder reads {', '.join(unrecorded)}")

    def _unrecorded(self) -> list[str]:
        """Topics this robot writes that a recorder on the domain does not read yet (a
        recorder subscribes to a topic only once it has seen a writer of it)."""
        recorders = self._recorders.update()
        if not recorders:
            return []
        return [t for t in self.bus.unrecorded(recorders) if t != STATUS_TOPIC]

    def _take_statuses(self) -> None:
        """Read what robots said (polled: statuses must be seen before the clock runs)."""
        for sample in self._status_reader.take(N=256):
            if sample.sample_info.valid_data:
                data = to_data(sample, STATUS_TYPE)
                self.statuses[data["robot"]] = Status(**{k: data[k] for k in Status.__slots__})
                self._quiet_since = None

    def _poll(self) -> None:
        self._take_statuses()
        self.clock.call_later(POLL, self._poll)

    def _say(self, *, ready: bool = True) -> None:
        engine = self.engine
        status = Status(
            self.robot,
            ready,
            not engine.idle,
            engine.next_timer is not None,
            engine.completed,
            "; ".join(engine.where()),
        )
        if status != self._said:
            self._said = status
            data = {k: getattr(status, k) for k in Status.__slots__}
            self.bus.publish(
                STATUS_TOPIC, data, msgtype=STATUS_TYPE, sender=self.robot, qos=KEEP_ALL
            )

    def _over(self) -> bool:
        """After each callback: say how the robot is; True once the mission is over."""
        self._say()
        if self.interrupted:
            return self.engine.idle
        quiet = all(
            r in self.statuses and not (self.statuses[r].busy or self.statuses[r].timer)
            for r in self.robots
        )
        if not quiet or self.bus.pending:
            self._quiet_since = None
            return False
        now = time.monotonic()
        if self._quiet_since is None:
            self._quiet_since = now
            self.clock.call_later(self.settle, lambda: None)  # look again then
        return now - self._quiet_since >= self.settle

    def interrupt(self) -> None:
        """Ctrl-C: stop the robot through its safe-state handler (from a signal handler)."""
        self.interrupted = True
        self.clock.call_soon(lambda: self.engine.stop(safe=True))


def _talk(publisher: Endpoint, subscriber: Endpoint) -> bool:
    """Whether DDS will match the pair (a pair fame check refuses never will: no waiting)."""
    return not pair_problems(publisher.qos, subscriber.qos, publisher.msgtype, subscriber.msgtype)
