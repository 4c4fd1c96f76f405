"""The robot handle: what scripts, conditions and skills see of the robot they run on.

It implements :class:`robotale.fame_runtime.skills.Robot`. Relative topic names live in the
robot's namespace (``odom`` -> ``/tractor_1/odom``); names starting with ``/`` are global.
"""

from __future__ import annotations

from collections.abc import Callable, Iterable
from types import MappingProxyType
from typing import Any

from robotale.fame_runtime.bus import Bus, Envelope, Subscription
from robotale.fame_runtime.clock import Clock
from robotale.fame_runtime.qos import QoS


class RobotHandle:
    """One robot's name, type, bus, clock and variables, shared by its engine's tokens."""

    def __init__(
        self,
        name: str,
        robot_type: str,
        bus: Bus,
        clock: Clock,
        variables: dict[str, Any],
        on_change: Callable[[Iterable[str]], None],
    ) -> None:
        self.name = name
        self.robot_type = robot_type
        self.bus = bus
        self.clock = clock
        self._variables = variables
        #: the process variables, read-only (scripts assign to them; skills return outputs)
        self.variables = MappingProxyType(variables)
        self._on_change = on_change
        self._latest: dict[str, Any] = {}
        self._subscriptions: list[Subscription] = []

    def __repr__(self) -> str:
        return f"RobotHandle({self.name!r}, {self.robot_type!r})"

    def now(self) -> float:
        """The engine clock's time (seconds since the Unix epoch)."""
        return self.clock.now()

    def topic(self, name: str) -> str:
        """``name`` inside the robot's namespace (``odom`` -> ``/tractor_1/odom``)."""
        return name if name.startswith("/") else f"/{self.name}/{name}"

    def publish(self, topic: str, data: Any, msgtype: str, qos: QoS | None = None) -> Envelope:
        return self.bus.publish(self.topic(topic), data, msgtype=msgtype, sender=self.name, qos=qos)

    def subscribe(
        self, topic: str, callback: Callable[[Envelope], None], msgtype: str | None = None
    ) -> Subscription:
        """Subscribe on the robot's behalf; the engine drops it when it stops."""
        subscription = self.bus.subscribe(
            self.topic(topic), callback, msgtype=msgtype, owner=self.name
        )
        self._subscriptions.append(subscription)
        return subscription

    def latest(self, topic: str, default: Any = None) -> Any:
        """The data of the last message on ``topic`` (``default`` before the first one).

        The first call subscribes, so it sees messages from then on. Conditions that read a
        topic this way are re-evaluated whenever one of these topics gets a message.
        """
        full = self.topic(topic)
        if full not in self._latest:
            self._latest[full] = default
            self.subscribe(full, self._remember)
        value = self._latest[full]
        return default if value is None else value

    def set(self, **values: Any) -> None:
        """Set variables from outside a script (a skill, the simulation); conditional events
        that read them are re-evaluated."""
        self._variables.update(values)
        self._on_change(values)

    def close(self) -> None:
        """Drop every subscription made through this handle."""
        for subscription in self._subscriptions:
            subscription.unsubscribe()
        self._subscriptions.clear()
        self._latest.clear()

    def _remember(self, envelope: Envelope) -> None:
        self._latest[envelope.topic] = envelope.data
        self._on_change(("robot",))
