"""Robots that do not hear a signal while they are busy (a world's ``busy_ignores``).

robotale's engine starts a new instance for every signal a start event hears, however many
instances already run. The thesis' tractors apparently did not: 7.2.2 puts the
`weed_position` messages no tractor received down to "tractors being busy at the moment the
drone transmitted the message", as if their engine ran a robot's process one instance at a
time, so that a tractor still handling a weed had no start event listening.
``busy_ignores: [weed_position]`` in a robot group of the world file gives its robots that
behaviour: a message on one of those signals that arrives while an instance of the robot's
process runs is not delivered to it, so no instance starts, no ``weed_position?`` is tagged
and nobody answers it.

It acts on the deliveries to the robot's engine only: the message was sent (the recorder sees
every publish) and other robots still hear it.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from typing import Any

from robotale.fame_runtime.bus import Bus, Envelope, Subscription
from robotale.fame_runtime.engine import Engine


class BusyDeaf:
    """The engines' view of a bus, on which the robots named in ``ignores`` do not hear those
    topics while their engine runs an instance (``engines`` is set once they exist).
    Everything else passes to ``bus`` unchanged."""

    def __init__(self, bus: Bus, ignores: Mapping[str, frozenset[str]]) -> None:
        self._bus = bus
        self._ignores = ignores  # robot -> topics
        self.engines: Mapping[str, Engine] = {}
        #: told of each message a busy robot did not hear (the robot, the envelope)
        self.observer: Callable[[str, Envelope], None] | None = None

    def __getattr__(self, name: str) -> Any:
        return getattr(self._bus, name)

    def subscribe(self, topic, callback, *, msgtype=None, qos=None, owner="") -> Subscription:
        if topic in self._ignores.get(owner, frozenset()):
            callback = self._while_idle(owner, callback)
        return self._bus.subscribe(topic, callback, msgtype=msgtype, qos=qos, owner=owner)

    def _while_idle(
        self, robot: str, callback: Callable[[Envelope], None]
    ) -> Callable[[Envelope], None]:
        def deliver(envelope: Envelope) -> None:
            if self.engines[robot].idle:
                callback(envelope)
            elif self.observer is not None:
                self.observer(robot, envelope)

        return deliver


def ignores_of(groups: Mapping[str, tuple[str, ...]], robots: Mapping[str, str]) -> dict:
    """Per robot, the topics it does not hear while busy: ``groups`` maps a robot group to its
    ``busy_ignores`` signal names, ``robots`` each robot to its group."""
    return {
        robot: frozenset(f"/{name}" for name in groups.get(group, ()))
        for robot, group in robots.items()
        if groups.get(group)
    }
