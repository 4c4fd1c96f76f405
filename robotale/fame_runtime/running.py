"""The activity instances one robot has started and not yet ended: each is tagged as it starts
and ends (``complete``, or ``ate_abort`` when it is interrupted or cancelled) and numbered for
an observer apart from the tags (a simulation's ground truth numbers instances, tags do not).
"""

from __future__ import annotations

import contextlib
from collections.abc import Callable, Hashable, Iterator
from enum import StrEnum

from robotale.fame_runtime.tags import Lifecycle, Tagger

#: told of every activity instance as it starts and ends (robot, instance number, activity,
#: an :class:`Ending`'s text)
ActivityObserver = Callable[[str, int, str, str], None]


class Ending(StrEnum):
    """What the activity observer is told of an activity instance."""

    START = "start"
    COMPLETED = "completed"
    INTERRUPTED = "interrupted"  # by an interrupting boundary event or event sub-process
    CANCELLED = "cancelled"


class RunningActivities:
    """One robot's activity instances that started and have not ended, by the token (any
    key) running each."""

    def __init__(self, robot: str, tag: Tagger) -> None:
        self.robot, self.tag = robot, tag
        self.observer: ActivityObserver | None = None
        self._running: dict[Hashable, tuple[str, int]] = {}  # key -> activity, number
        self._count = 0
        #: how a cancel ends the activities it reaches: ``interrupted`` while an interrupting
        #: boundary event or event sub-process takes over, else ``cancelled``
        self._ending = Ending.CANCELLED

    def begin(self, key: Hashable, label: str) -> None:
        """``key``'s activity starts: tagged, and remembered until it ends."""
        self.tag(label, Lifecycle.START)
        self._count += 1
        self._running[key] = (label, self._count)
        if self.observer is not None:
            self.observer(self.robot, self._count, label, Ending.START.value)

    def end(self, key: Hashable, lifecycle: Lifecycle) -> None:
        """``key``'s activity, if one runs, ends: ``complete``, or ``ate_abort`` when it was
        interrupted or cancelled."""
        running = self._running.pop(key, None)
        if running is None:
            return
        label, number = running
        self.tag(label, lifecycle)
        if self.observer is not None:
            how = Ending.COMPLETED if lifecycle == Lifecycle.COMPLETE else self._ending
            self.observer(self.robot, number, label, how.value)

    @contextlib.contextmanager
    def interrupting(self) -> Iterator[None]:
        """The activities cancelled meanwhile were interrupted (an interrupting boundary event
        or event sub-process), not merely cancelled."""
        before, self._ending = self._ending, Ending.INTERRUPTED
        try:
            yield
        finally:
            self._ending = before
