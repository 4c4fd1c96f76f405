"""Buses: signals are topics (guideline G3).

A :class:`Bus` carries :class:`Envelope` s from publishers to the subscribers of a topic. The
in-process bus delivers through the shared clock, never inside ``publish``: a throw in one
engine cannot re-enter another engine's step, and delivery order is deterministic. A DDS bus,
where each robot's engine is its own process, implements the same interface.
"""

from __future__ import annotations

import itertools
from collections import defaultdict
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any, Protocol

from robotale.fame_runtime.clock import Clock
from robotale.fame_runtime.qos import DEFAULT_QOS, QoS


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


class InProcessBus:
    """Topics inside one process, delivered through the clock after ``latency`` seconds."""

    def __init__(self, clock: Clock, *, latency: float = 0.0, drop: DropRule | None = None):
        self.clock = clock
        self.latency = latency
        self.drop = drop
        self._subscribers: dict[str, list[Subscription]] = defaultdict(list)
        self._taps: list[Subscription] = []
        self._ids = itertools.count(1)
        #: deliveries scheduled on the clock but not made yet (a mission is not over while
        #: a message is in flight)
        self.pending = 0

    def new_msg_id(self) -> str:
        """A message id unique on this bus (``m_1``, ``m_2`` ... as in the thesis' log)."""
        return f"m_{next(self._ids)}"

    def publish(self, topic, data, *, msgtype, sender="", msg_id="", qos=None) -> Envelope:
        envelope = Envelope(
            topic, data, msgtype, self.clock.now(), sender, msg_id, qos or DEFAULT_QOS
        )
        for tap in list(self._taps):
            tap.callback(envelope)
        for subscription in list(self._subscribers.get(topic, ())):
            if self.drop and self.drop(envelope, subscription):
                continue
            self.pending += 1
            self.clock.call_later(self.latency, self._delivery(subscription, envelope))
        return envelope

    def subscribe(self, topic, callback, *, msgtype=None, qos=None, owner="") -> Subscription:
        subscription = Subscription(topic, callback, msgtype, qos or DEFAULT_QOS, owner, _bus=self)
        self._subscribers[topic].append(subscription)
        return subscription

    def tap(self, callback) -> Subscription:
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
                subscription.callback(envelope)

        return deliver
