"""A simulated run watched as it goes (``robotale simulate --live``): the monitor of live
robots (:class:`~robotale.results.monitor.Monitor`) on the simulation's in-process bus and
clock, storing the run's tags as a live log, replaying them on the robots' pools and raising
its alerts in simulated time, as ``robotale monitor`` does for robots on DDS."""

from __future__ import annotations

from collections import defaultdict
from collections.abc import Callable
from pathlib import Path
from typing import Any, TextIO, cast

from neo4j import Driver

from robotale.discovery.online import pool_replays
from robotale.ekg.growing import GrowingLog
from robotale.ekg.live import LiveLog
from robotale.fame_runtime.bus import Bus, Envelope, InProcessBus, Subscription
from robotale.fame_runtime.clock import RunningClock
from robotale.fame_runtime.qos import DEFAULT_QOS, QoS
from robotale.results.monitor import TICK, Limits, Monitor

#: called once the live log ``name`` holds its first tag (to say where to follow it)
Announce = Callable[[str], None]


class Overheard:
    """The simulation's bus as the monitor hears it: each message the moment it is published,
    as the run's recorder taps it. The monitor is no robot on the simulated radio links, so it
    hears every robot's tags, all of them and in the order they were sent, as the bag holds
    them. What the monitor publishes (its alerts) goes onto the bus like any message."""

    def __init__(self, bus: InProcessBus) -> None:
        self.bus = bus
        # a simulation's clock runs its callbacks itself (a SimClock), as the monitor needs
        self.clock = cast(RunningClock, bus.clock)
        self._callbacks: dict[str, list[Subscription]] = defaultdict(list)
        bus.tap(self._heard)

    def subscribe(
        self, topic: str, callback: Callable[[Envelope], None], **reader: Any
    ) -> Subscription:
        """``reader``: the ``msgtype``, ``qos`` and ``owner`` a bus's subscription takes."""
        qos: QoS = reader.get("qos") or DEFAULT_QOS
        msgtype, owner = reader.get("msgtype"), reader.get("owner", "")
        subscription = Subscription(topic, callback, msgtype, qos, owner, _bus=self)
        self._callbacks[topic].append(subscription)
        return subscription

    def _remove(self, subscription: Subscription) -> None:
        self._callbacks[str(subscription.topic)].remove(subscription)

    def publish(self, topic: str, data: Any, **options: Any) -> Envelope:
        return self.bus.publish(topic, data, **options)

    def tap(self, callback: Callable[[Envelope], None]) -> Subscription:
        return self.bus.tap(callback)

    def _heard(self, envelope: Envelope) -> None:
        for subscription in list(self._callbacks.get(envelope.topic, ())):
            # a reader of another type never matches a writer on DDS
            if subscription.msgtype in (None, envelope.msgtype):
                subscription.callback(envelope)


class WatchedRun:
    """One simulated run under the monitor: made before its mission starts, ended after. Its
    tags are stored as the live log ``name`` and as a growing event knowledge graph, as
    ``robotale monitor`` stores a run on DDS."""

    def __init__(
        self,
        driver: Driver,
        name: str,
        model: Path,
        robots: list[str],
        bus: InProcessBus,
        limits: Limits,
        out: TextIO,
        announce: Announce | None = None,
        relay: Bus | None = None,
    ) -> None:
        """``relay``: another bus the alerts are published on (see :class:`Monitor`)."""
        self.name, self.announce, self.announced = name, announce, False
        replays = pool_replays(model, robots)
        # refused here, before the run starts, when a log no monitor wrote has that name
        self.graph = GrowingLog(driver, name)
        try:
            # the graph is handed to the monitor once the run is announced: the dashboard's
            # first answer does not wait behind the graph's first append (which has Neo4j plan
            # each of its queries)
            self.monitor = Monitor(
                Overheard(bus), LiveLog(driver, name), replays, limits, out, relay=relay
            )
        except BaseException:
            self.graph.close()
            raise
        if announce is None:
            self.monitor.graph = self.graph
        self._tick(bus)

    def _tick(self, bus: InProcessBus) -> None:
        """The monitor looks at the robots' silences and the time things take, and hands what
        it heard to its writers, every :data:`TICK` simulated seconds, as it does every
        :data:`TICK` wall seconds on DDS."""

        def look() -> None:
            self.monitor.watch()
            self.monitor.store()
            self._announce()
            bus.clock.call_later(TICK, look)

        bus.clock.call_later(TICK, look)

    def _announce(self) -> None:
        """Say where the run is followed, once the live log holds a tag. On the simulation's
        thread, which waits meanwhile: a dashboard in this process answers sooner so."""
        if self.announce is not None and self.monitor.live.count and not self.announced:
            self.announced = True
            self.announce(self.name)
            self.monitor.graph = self.graph

    def end(self) -> int:
        """A last look at the run as it ended, everything stored; how many tags were."""
        self.monitor.watch()
        self.monitor.graph = self.graph  # also when nothing was announced
        self.monitor.finish()
        return self.monitor.live.count
