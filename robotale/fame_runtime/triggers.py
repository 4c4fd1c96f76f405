"""Arming catching events: what makes a waiting token, a boundary event, an event sub-process
or a start event fire.

- signal: a subscription to the signal's topic (guideline G3);
- timer: clock callbacks at the definition's fire times (repeating for cycles when asked);
- conditional: a watch re-evaluated whenever a variable it reads changes (and, if it reads
  ``robot``, whenever a topic read through ``robot.latest`` gets a message); it fires when the
  condition *becomes* true, or at once if it is true when armed;
- error: a catcher for errors thrown inside the scope and for messages on the robot's error
  topic ``/<robot>/<error name>`` (``std_msgs/msg/Empty``, guideline G4). A message on an error
  topic is handled by one catcher: the innermost one armed.

Every ``arm`` returns a function that disarms. Firing never re-enters the engine: the
``schedule`` callback it is given queues the work.
"""

from __future__ import annotations

import itertools
from collections import defaultdict
from collections.abc import Callable, Iterable
from typing import Any

from robotale.errors import ModelError
from robotale.fame_runtime.bus import Bus, Envelope, Subscription
from robotale.fame_runtime.clock import Clock, Timer
from robotale.fame_runtime.expressions import Compiled, substitute
from robotale.fame_runtime.kinds import EventKind
from robotale.fame_runtime.plan import EMPTY_MSGTYPE, Trigger
from robotale.fame_runtime.timers import parse_timer

Fire = Callable[[Envelope | None], None]
Disarm = Callable[[], None]


def _nothing() -> None:
    return None


class _Watch:
    __slots__ = ("condition", "fire", "last", "names", "order", "repeat")

    def __init__(self, condition: Compiled, fire: Fire, repeat: bool, order: int) -> None:
        self.order = order
        self.condition = condition
        self.fire = fire
        self.repeat = repeat
        self.last = False
        self.names = condition.reads


class _Catcher:
    __slots__ = ("depth", "fire", "order")

    def __init__(self, depth: float, order: int, fire: Fire) -> None:
        self.depth, self.order, self.fire = depth, order, fire


class Triggers:
    """The armed catching events of one engine."""

    def __init__(
        self,
        robot: str,
        bus: Bus,
        clock: Clock,
        schedule: Callable[[Callable[[], None]], None],
        evaluate: Callable[[Any], Any],
        env: dict[str, Any],
        variables: dict[str, Any],
    ) -> None:
        self.robot, self.bus, self.clock = robot, bus, clock
        self.schedule = schedule
        self.evaluate = evaluate  # a compiled condition -> its value, errors explained
        self.env, self.variables = env, variables
        self._watches: dict[str, set[_Watch]] = defaultdict(set)
        self._catchers: dict[str, list[_Catcher]] = defaultdict(list)
        self._error_topics: dict[str, Subscription] = {}
        self._order = itertools.count()
        #: when each armed timer fires next (a mission is not over while one is armed)
        self._timers: dict[int, float] = {}

    def next_timer(self) -> float | None:
        """When the next armed timer fires, or None when no timer is armed."""
        return min(self._timers.values(), default=None)

    def arm(
        self, trigger: Trigger, fire: Fire, *, repeat: bool = False, depth: float = 0
    ) -> Disarm:
        if trigger.kind == EventKind.SIGNAL:
            return self._signal(trigger, fire)
        if trigger.kind == EventKind.TIMER:
            return self._timer(trigger, fire, repeat)
        if trigger.kind == EventKind.CONDITIONAL:
            return self._conditional(trigger, fire, repeat)
        return self._error(trigger, fire, depth)

    def _signal(self, trigger: Trigger, fire: Fire) -> Disarm:
        def deliver(envelope: Envelope) -> None:
            self.schedule(lambda: fire(envelope))

        subscription = self.bus.subscribe(
            trigger.topic,
            deliver,
            msgtype=trigger.msgtype or None,
            qos=trigger.qos,
            owner=self.robot,
        )
        return subscription.unsubscribe

    def _timer(self, trigger: Trigger, fire: Fire, repeat: bool) -> Disarm:
        spec = trigger.timer
        if spec is None:
            return _nothing
        if spec.deferred:
            try:
                text = str(substitute(spec.text, self.variables, self.env))
                spec = parse_timer(spec.kind, text)
            except (ValueError, NameError) as error:
                raise ModelError(f"timer {trigger.label} of robot {self.robot}: {error}") from None
        times = spec.fire_times(self.clock.now())
        pending: list[Timer] = []
        key = next(self._order)

        def schedule_next() -> None:
            when = next(times, None)
            if when is not None:
                pending[:] = [self.clock.call_at(when, ring)]
                self._timers[key] = when

        def ring() -> None:
            self._timers.pop(key, None)
            if repeat:
                schedule_next()
            self.schedule(lambda: fire(None))

        def disarm() -> None:
            self._timers.pop(key, None)
            for timer in pending:
                timer.cancel()

        schedule_next()
        return disarm

    def _conditional(self, trigger: Trigger, fire: Fire, repeat: bool) -> Disarm:
        assert trigger.condition is not None  # the deployer compiles every condition
        watch = _Watch(trigger.condition, fire, repeat, next(self._order))
        for name in watch.names:
            self._watches[name].add(watch)
        self._check(watch)

        def disarm() -> None:
            for name in watch.names:
                self._watches[name].discard(watch)

        return disarm

    def changed(self, names: Iterable[str]) -> None:
        """Re-evaluate the conditions that read any of ``names``."""
        if not self._watches:
            return
        due: set[_Watch] = set()
        for name in names:
            due |= self._watches.get(name, set())
        for watch in sorted(due, key=lambda w: w.order):
            self._check(watch)

    def _check(self, watch: _Watch) -> None:
        value = bool(self.evaluate(watch.condition))
        if value and not watch.last:
            if not watch.repeat:
                for name in watch.names:
                    self._watches[name].discard(watch)
            self.schedule(lambda: watch.fire(None))
        watch.last = value

    def _error(self, trigger: Trigger, fire: Fire, depth: float) -> Disarm:
        catcher = _Catcher(depth, next(self._order), fire)
        self._catchers[trigger.topic].append(catcher)
        if trigger.topic and trigger.topic not in self._error_topics:
            name = trigger.topic

            def raised(envelope: Envelope) -> None:
                self.schedule(lambda: self._error_message(name, envelope))

            self._error_topics[trigger.topic] = self.bus.subscribe(
                f"/{self.robot}/{trigger.topic}",
                raised,
                msgtype=EMPTY_MSGTYPE,
                owner=self.robot,
            )

        def disarm() -> None:
            catchers = self._catchers[trigger.topic]
            if catcher in catchers:
                catchers.remove(catcher)
            if not catchers and trigger.topic in self._error_topics:
                self._error_topics.pop(trigger.topic).unsubscribe()

        return disarm

    def _error_message(self, name: str, envelope: Envelope) -> None:
        catchers = self._catchers.get(name)
        if catchers:
            innermost = max(catchers, key=lambda c: (c.depth, -c.order))
            innermost.fire(envelope)
