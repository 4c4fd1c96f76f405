"""Buses: signals are topics (guideline G3).

A :class:`Bus` carries :class:`Envelope` s from publishers to the subscribers of a topic. The
in-process bus delivers through the shared clock, never inside ``publish``: a throw in one
engine cannot re-enter another engine's step, and delivery order is deterministic. A DDS bus
(:mod:`robotale.fame_runtime.dds`), where each robot's engine is its own process, implements
the same interface.

Both honour the QoS the way DDS does, so a simulation cannot succeed where ROS 2 would not:
a publisher and a subscriber whose QoS or message types do not match
(:func:`~robotale.fame_runtime.qos.pair_problems`, the rules ``fame check`` applies) never
talk; a transient-local publisher keeps its last ``depth`` messages for subscribers that
come later and ask for them; only best-effort deliveries are lost at random (``loss``).

A :class:`Network` makes the in-process bus behave like a radio link: each delivery waits a
latency drawn per message and is lost with a probability that can grow with the distance
between sender and receiver; a reliable delivery that is lost is resent every ``retry`` seconds
until it arrives or its ``deadline`` passes, a best-effort one is gone. A robot's messages to
itself (a skill's commands to its own drivers, its odometry to its skills) keep their order, as
one writer's samples do for a DDS reader: a stop command never overtakes the drive command
published before it, which would leave the robot driving on.
"""

from __future__ import annotations

import itertools
import logging
import random
from collections import defaultdict, deque
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from typing import Any, Protocol

from robotale.fame_runtime.clock import Clock
from robotale.fame_runtime.qos import DEFAULT_QOS, QoS, pair_problems

_log = logging.getLogger(__name__)


@dataclass(frozen=True, slots=True)
class Envelope:
    """One message on a topic: ROS-typed ``data`` (a dict, or a Tag on tag topics) plus the
    facts a tag needs (who sent it, the message id receivers report, when)."""

    topic: str
    data: Any
    msgtype: str
    stamp: float
    sender: str = ""
    msg_id: str = ""
    qos: QoS = DEFAULT_QOS


@dataclass(eq=False)
class Subscription:
    topic: str | None  # None: a tap that sees every topic
    callback: Callable[[Envelope], None]
    msgtype: str | None = None
    qos: QoS = DEFAULT_QOS
    owner: str = ""
    active: bool = field(default=True)
    _bus: Any = field(default=None, repr=False)
    #: when the last delivery from its own robot is due (a robot's messages to itself keep
    #: their order)
    _local_due: float = field(default=float("-inf"), repr=False, compare=False)

    def unsubscribe(self) -> None:
        if self.active:
            self.active = False
            self._bus._remove(self)


class Bus(Protocol):
    """What engines need of a bus. Two optional members help them: ``new_msg_id()`` (message
    ids unique on the bus; engines otherwise use ``m_<robot>_<n>``, unique because robot
    namespaces are) and ``pending`` (deliveries in flight, so a mission knows it is over)."""

    def publish(
        self,
        topic: str,
        data: Any,
        *,
        msgtype: str,
        sender: str = "",
        msg_id: str = "",
        qos: QoS | None = None,
    ) -> Envelope: ...

    def subscribe(
        self,
        topic: str,
        callback: Callable[[Envelope], None],
        *,
        msgtype: str | None = None,
        qos: QoS | None = None,
        owner: str = "",
    ) -> Subscription: ...

    def tap(self, callback: Callable[[Envelope], None]) -> Subscription: ...


#: decides whether one delivery is lost (fault injection: a dropped message).
DropRule = Callable[[Envelope, Subscription], bool]

#: told what became of each delivery, apart from the subscribers (a simulation's ground truth):
#: the outcome (one of :data:`OUTCOMES`), the envelope and the subscription it was meant for
DeliveryObserver = Callable[[str, Envelope, Subscription], None]
#: what becomes of one delivery: handed to its subscriber; publisher and subscriber cannot talk
#: (QoS or message types); dropped by a fault; lost on the way (``loss``, the network); the
#: subscriber had left when it arrived
DELIVERED, QOS, FAULT, LOSS, LEFT = "delivered", "qos", "fault", "loss", "left"
OUTCOMES = (DELIVERED, QOS, FAULT, LOSS, LEFT)

#: a publisher as DDS sees it: one data writer per topic, sender, QoS and message type
WriterKey = tuple[str, str, QoS, str]


def reader_key(subscription: Subscription) -> tuple[str | None, str, QoS, str | None]:
    """A subscription as DDS sees it: a re-armed catch event is the same reader again."""
    return (subscription.topic, subscription.owner, subscription.qos, subscription.msgtype)


def mismatch_warning(envelope: Envelope, subscription: Subscription, reasons: list[str]) -> str:
    """The one sentence a run prints for a publisher and subscriber that never talk."""
    sender = envelope.sender or "a publisher"
    owner = subscription.owner or "a subscriber"
    return (
        f"{envelope.topic}: {sender} and {owner} cannot talk, so nothing {sender} publishes "
        f"there reaches {owner} ({'; '.join(reasons)})"
    )


def best_effort(offered: QoS, requested: QoS) -> bool:
    """Whether a delivery goes without acknowledgement (either side best effort)."""
    return "best_effort" in (offered.reliability, requested.reliability)


def _nowhere(_name: str) -> tuple[float, float] | None:
    """No robot's position is known (a module function, so a network can be pickled)."""
    return None


@dataclass(frozen=True)
class Link:
    """How messages travel from one robot to another."""

    latency: float = 0.01  # seconds, the mean
    jitter: float = 0.0  # seconds, the standard deviation (normal, never below zero)
    loss: float = 0.0  # probability that one transmission is lost, at distance 0
    loss_per_metre: float = 0.0  # added to ``loss`` per metre between the two robots
    retry: float = 0.05  # seconds between a reliable writer's resends
    deadline: float = 1.0  # seconds after which a reliable writer gives a message up


@dataclass
class Network:
    """A link for every pair of robots: ``links[(sender, receiver)]`` or ``default``.

    ``locate`` tells where a robot is (None when unknown, for example a subscriber that is not
    a robot); without a position, distance counts as zero.
    """

    default: Link = field(default_factory=Link)
    links: Mapping[tuple[str, str], Link] = field(default_factory=dict)
    locate: Callable[[str], tuple[float, float] | None] = _nowhere

    def link(self, sender: str, receiver: str) -> Link:
        return self.links.get((sender, receiver), self.default)

    def loss(self, link: Link, sender: str, receiver: str) -> float:
        if not link.loss_per_metre:
            return link.loss
        here, there = self.locate(sender), self.locate(receiver)
        if here is None or there is None:
            return link.loss
        distance: float = ((here[0] - there[0]) ** 2 + (here[1] - there[1]) ** 2) ** 0.5
        return min(1.0, link.loss + link.loss_per_metre * distance)


class InProcessBus:
    """Topics inside one process, delivered through the clock after ``latency`` seconds.

    ``drop`` loses chosen deliveries (fault injection: a link that is down); ``loss`` is the
    probability that a best-effort delivery is lost (reliable ones are resent by DDS, so they
    always arrive). ``network`` (a :class:`Network`) replaces the fixed ``latency`` with per-link
    latencies, losses and reliable resends. ``on_warning`` receives the sentence about each
    pair that cannot talk, once per pair (default: the ``logging`` warning); ``warnings`` keeps
    them all.
    """

    def __init__(
        self,
        clock: Clock,
        *,
        latency: float = 0.0,
        drop: DropRule | None = None,
        loss: float = 0.0,
        seed: int | None = None,
        on_warning: Callable[[str], None] | None = None,
        network: Network | None = None,
    ):
        self.clock = clock
        self.latency = latency
        self.network = network
        self.drop = drop
        self.loss = loss
        self._random = random.Random(seed)
        self.on_warning = on_warning or _log.warning
        self.warnings: list[str] = []
        self._warned: set[tuple[Any, ...]] = set()
        self._subscribers: dict[str, list[Subscription]] = defaultdict(list)
        self._taps: list[Subscription] = []
        self._ids = itertools.count(1)
        #: what each transient-local publisher keeps for subscribers that come later
        self._kept: dict[WriterKey, deque[Envelope]] = {}
        #: deliveries scheduled on the clock but not made yet (a mission is not over while
        #: a message is in flight)
        self.pending = 0
        #: told what became of every delivery (None: nobody asks)
        self.observer: DeliveryObserver | None = None

    def new_msg_id(self) -> str:
        """A message id unique on this bus (``m_1``, ``m_2`` ... as in the thesis' log)."""
        return f"m_{next(self._ids)}"

    def publish(
        self,
        topic: str,
        data: Any,
        *,
        msgtype: str,
        sender: str = "",
        msg_id: str = "",
        qos: QoS | None = None,
    ) -> Envelope:
        envelope = Envelope(
            topic, data, msgtype, self.clock.now(), sender, msg_id, qos or DEFAULT_QOS
        )
        for tap in list(self._taps):
            tap.callback(envelope)
        self._keep(envelope)
        for subscription in list(self._subscribers.get(topic, ())):
            if not self._talk(envelope, subscription):
                self._observe(QOS, envelope, subscription)
            elif self.drop and self.drop(envelope, subscription):
                self._observe(FAULT, envelope, subscription)
            elif self._lost(envelope, subscription):
                self._observe(LOSS, envelope, subscription)
            elif self.network is not None:
                self._transmit(subscription, envelope)
            else:
                self._send(subscription, envelope)
        return envelope

    def _observe(self, outcome: str, envelope: Envelope, subscription: Subscription) -> None:
        if self.observer is not None:
            self.observer(outcome, envelope, subscription)

    def subscribe(
        self,
        topic: str,
        callback: Callable[[Envelope], None],
        *,
        msgtype: str | None = None,
        qos: QoS | None = None,
        owner: str = "",
    ) -> Subscription:
        subscription = Subscription(topic, callback, msgtype, qos or DEFAULT_QOS, owner, _bus=self)
        self._subscribers[topic].append(subscription)
        if subscription.qos.durability == "transient_local":
            self._late_join(subscription)
        return subscription

    def _send(self, subscription: Subscription, envelope: Envelope) -> None:
        self.pending += 1
        self.clock.call_later(self.latency, self._delivery(subscription, envelope))

    def _transmit(self, subscription: Subscription, envelope: Envelope) -> None:
        """Send over the network: each try is lost with the link's probability; a reliable
        writer tries again every ``retry`` seconds until ``deadline``, best effort once."""
        network = self.network
        assert network is not None
        sender, receiver = envelope.sender, subscription.owner
        link = network.link(sender, receiver)
        chance = network.loss(link, sender, receiver)
        tries = 1 if best_effort(envelope.qos, subscription.qos) else _tries(link)
        for attempt in range(tries):
            if self._random.random() >= chance:
                delay = attempt * link.retry + self._latency(link)
                if sender and sender == receiver:
                    delay = self._in_order(subscription, delay)
                self.pending += 1
                self.clock.call_later(delay, self._delivery(subscription, envelope))
                return
        self._observe(LOSS, envelope, subscription)

    def _in_order(self, subscription: Subscription, delay: float) -> float:
        """``delay``, or longer so a robot's message to itself arrives after the one it
        published before on the same topic (the latency is still drawn: the other links'
        draws stay as they were)."""
        now = self.clock.now()
        subscription._local_due = max(now + delay, subscription._local_due)
        return subscription._local_due - now

    def _latency(self, link: Link) -> float:
        if not link.jitter:
            return link.latency
        return max(0.0, self._random.gauss(link.latency, link.jitter))

    def _talk(self, envelope: Envelope, subscription: Subscription) -> bool:
        """Whether the envelope's publisher is matched with the subscriber (warn once if not)."""
        reasons = pair_problems(
            envelope.qos, subscription.qos, envelope.msgtype, subscription.msgtype
        )
        if not reasons:
            return True
        pair = (
            envelope.topic,
            envelope.sender,
            envelope.qos,
            envelope.msgtype,
            reader_key(subscription),
        )
        if pair not in self._warned:
            self._warned.add(pair)
            warning = mismatch_warning(envelope, subscription, reasons)
            self.warnings.append(warning)
            self.on_warning(warning)
        return False

    def _lost(self, envelope: Envelope, subscription: Subscription) -> bool:
        if not self.loss or not best_effort(envelope.qos, subscription.qos):
            return False
        return self._random.random() < self.loss

    def _keep(self, envelope: Envelope) -> None:
        """A transient-local publisher keeps its last ``depth`` messages (all: keep_all)."""
        qos = envelope.qos
        if qos.durability != "transient_local":
            return
        key = (envelope.topic, envelope.sender, qos, envelope.msgtype)
        if key not in self._kept:
            self._kept[key] = deque(maxlen=qos.depth if qos.history == "keep_last" else None)
        self._kept[key].append(envelope)

    def _late_join(self, subscription: Subscription) -> None:
        """A transient-local subscriber gets what matched transient-local publishers kept
        (its own ``depth`` last of them), as a DDS reader gets the writers' history."""
        for (topic, *_), kept in self._kept.items():
            if topic != subscription.topic or not kept or not self._talk(kept[0], subscription):
                continue
            samples = list(kept)
            if subscription.qos.history == "keep_last":
                samples = samples[-subscription.qos.depth :]
            for envelope in samples:
                self._send(subscription, envelope)

    def tap(self, callback: Callable[[Envelope], None]) -> Subscription:
        """See every envelope at publish time (a recorder); taps are never dropped."""
        subscription = Subscription(None, callback, _bus=self)
        self._taps.append(subscription)
        return subscription

    def topics(self) -> list[str]:
        return sorted(t for t, subs in self._subscribers.items() if subs)

    def _remove(self, subscription: Subscription) -> None:
        group = self._taps if subscription.topic is None else self._subscribers[subscription.topic]
        if subscription in group:
            group.remove(subscription)

    def _delivery(self, subscription: Subscription, envelope: Envelope) -> Callable[[], None]:
        def deliver() -> None:
            self.pending -= 1
            # A subscriber that left between publish and delivery does not receive it.
            if subscription.active:
                self._observe(DELIVERED, envelope, subscription)
                subscription.callback(envelope)
            else:
                self._observe(LEFT, envelope, subscription)

        return deliver


def _tries(link: Link) -> int:
    """How many times a reliable writer sends: the first time and each resend in the deadline."""
    return 1 + int(link.deadline / link.retry + 1e-9) if link.retry > 0 else 1
