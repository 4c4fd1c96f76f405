"""The bus side of the rclnodejs node shim FAME's JavaScript scripts see as
``environment.variables.node`` (its JavaScript side is ``rclnodejs.js``).

A script's ``createPublisher(...).publish``, ``createSubscription``, ``destroySubscription`` and
``createClient(...).sendRequest`` come out of the runtime's outbox as effects; :class:`RosNode`
turns them into publications and subscriptions on the robot's bus, and hands what arrives to
the script's callbacks on the robot's engine, never inside the bus. Topics without a leading
``/`` are in the robot's namespace; a service call is a request published on
``<service>/request`` and the first message on ``<service>/response`` after it.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

from robotale.fame_runtime.bus import Bus, Envelope, Subscription

#: the effects a script's node shim leaves in the outbox
EFFECTS = frozenset({"pub", "sub", "unsub", "req"})

#: hands a message to the script callback with this id (a subscription's or a service call's)
Deliver = Callable[[int, Envelope], None]


class RosNode:
    """One robot's node shim on its bus: ``schedule`` queues work on the robot's engine;
    ``on_message`` and ``on_response`` run a subscription's or a service call's callback."""

    def __init__(
        self,
        robot: str,
        bus: Bus,
        *,
        schedule: Callable[[Callable[[], Any]], None],
        on_message: Deliver,
        on_response: Deliver,
    ) -> None:
        self.robot, self.bus, self.schedule = robot, bus, schedule
        self.on_message, self.on_response = on_message, on_response
        self._subscriptions: dict[int, Subscription] = {}
        self._calls: dict[int, tuple[Subscription, str]] = {}

    def apply(self, effect: list[Any]) -> None:
        """Carry out one of the :data:`EFFECTS` a script left."""
        kind = effect[0]
        if kind == "pub":
            self.bus.publish(
                self._topic(effect[1]), effect[3], msgtype=effect[2], sender=self.robot
            )
        elif kind == "sub":
            self._subscribe(effect[1], effect[2], effect[3])
        elif kind == "unsub":
            subscription = self._subscriptions.pop(effect[1], None)
            if subscription is not None:
                subscription.unsubscribe()
        elif kind == "req":
            self._request(effect[1], effect[2], effect[3], effect[4])

    def close(self) -> None:
        """Drop the subscriptions scripts made (the engine stops or restarts)."""
        for subscription in (*self._subscriptions.values(), *(s for s, _ in self._calls.values())):
            subscription.unsubscribe()
        self._subscriptions.clear()
        self._calls.clear()

    def _topic(self, name: str) -> str:
        return name if name.startswith("/") else f"/{self.robot}/{name}"

    def _subscribe(self, sub_id: int, topic: str, msgtype: str) -> None:
        def deliver(envelope: Envelope) -> None:
            self.schedule(lambda: self.on_message(sub_id, envelope))

        self._subscriptions[sub_id] = self.bus.subscribe(
            self._topic(topic), deliver, msgtype=msgtype, owner=self.robot
        )

    def _request(self, call_id: int, service: str, msgtype: str, request: Any) -> None:
        topic = self._topic(service)

        def deliver(envelope: Envelope) -> None:
            entry = self._calls.pop(call_id, None)
            if entry is not None:
                entry[0].unsubscribe()
                self.schedule(lambda: self.on_response(call_id, envelope))

        subscription = self.bus.subscribe(
            f"{topic}/response", deliver, msgtype=msgtype, owner=self.robot
        )
        self._calls[call_id] = (subscription, topic)
        self.bus.publish(f"{topic}/request", request, msgtype=msgtype, sender=self.robot)
