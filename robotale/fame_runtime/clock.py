"""Clocks: the one notion of time that engines, skills, the simulated world and tags share.

:class:`SimClock` is a discrete-event scheduler. Simulated time jumps from one scheduled
callback to the next, so a run goes as fast as the machine allows; ``run(pace=1.0)`` paces it
to wall time for a person watching. Time is seconds since the Unix epoch, so tag stamps are
real datetimes. :class:`WallClock` is real time, for engines that run one per process.
"""

from __future__ import annotations

import heapq
import itertools
import threading
import time
from collections.abc import Callable
from typing import Protocol


class Timer:
    """A scheduled callback; ``cancel()`` makes sure it never runs."""

    __slots__ = ("callback", "cancelled", "when")

    def __init__(self, when: float, callback: Callable[[], None]) -> None:
        self.when = when
        self.callback = callback
        self.cancelled = False

    def cancel(self) -> None:
        self.cancelled = True


class Clock(Protocol):
    def now(self) -> float: ...

    def call_at(self, when: float, callback: Callable[[], None]) -> Timer: ...

    def call_later(self, delay: float, callback: Callable[[], None]) -> Timer: ...

    def call_soon(self, callback: Callable[[], None]) -> Timer: ...


class SimClock:
    """Simulated time driven by a queue of callbacks.

    Callbacks scheduled for the same instant run in the order they were scheduled, which keeps
    runs deterministic for a seed.
    """

    def __init__(self, start: float = 0.0) -> None:
        self._now = float(start)
        self._queue: list[tuple[float, int, Timer]] = []
        self._order = itertools.count()

    def now(self) -> float:
        return self._now

    def call_at(self, when: float, callback: Callable[[], None]) -> Timer:
        timer = Timer(max(float(when), self._now), callback)
        heapq.heappush(self._queue, (timer.when, next(self._order), timer))
        return timer

    def call_later(self, delay: float, callback: Callable[[], None]) -> Timer:
        return self.call_at(self._now + max(0.0, delay), callback)

    def call_soon(self, callback: Callable[[], None]) -> Timer:
        return self.call_at(self._now, callback)

    def next_time(self) -> float | None:
        """When the next live callback is due, or None if nothing is scheduled."""
        while self._queue and self._queue[0][2].cancelled:
            heapq.heappop(self._queue)
        return self._queue[0][0] if self._queue else None

    def step(self) -> bool:
        """Run the next live callback; False when nothing is scheduled."""
        due = self.next_time()
        if due is None:
            return False
        _, _, timer = heapq.heappop(self._queue)
        self._now = due
        timer.callback()
        return True

    def run(
        self,
        until: float | None = None,
        stop_when: Callable[[], bool] | None = None,
        pace: float | None = None,
    ) -> float:
        """Run callbacks until ``until`` (absolute time), ``stop_when()`` or an empty queue.

        With ``pace`` (simulated seconds per wall second) the run sleeps so that a person can
        follow it. Returns the time reached; reaching ``until`` sets the clock to it.
        """
        wall_start, sim_start = time.monotonic(), self._now
        while not (stop_when and stop_when()):
            due = self.next_time()
            if due is None or (until is not None and due > until):
                break
            if pace:
                lag = (due - sim_start) / pace - (time.monotonic() - wall_start)
                if lag > 0:
                    time.sleep(lag)
            self.step()
        if until is not None and self._now < until and not (stop_when and stop_when()):
            self._now = until
        return self._now


class WallClock:
    """Real time, for engines that talk to the world (one process per robot over DDS).

    Callbacks run on the thread that calls :meth:`run`, in the order they fall due; other
    threads (DDS listeners) and signal handlers may schedule at any time, which wakes the
    loop. ``start`` (seconds since the Unix epoch) makes the clock read that instant now and
    run at the wall's pace from there (``timeDate`` timers in a rehearsal); ``offset`` shifts
    it by that many seconds instead, so processes started one after the other share a time.
    """

    def __init__(self, start: float | None = None, *, offset: float | None = None) -> None:
        if offset is None:
            offset = 0.0 if start is None else start - time.time()
        self.offset = offset
        self._queue: list[tuple[float, int, Timer]] = []
        self._order = itertools.count()
        # reentrant: a signal handler may schedule while the loop holds the lock
        self._wake = threading.Condition(threading.RLock())
        self._stopped = False

    def now(self) -> float:
        return time.time() + self.offset

    def call_at(self, when: float, callback: Callable[[], None]) -> Timer:
        timer = Timer(float(when), callback)
        with self._wake:
            heapq.heappush(self._queue, (timer.when, next(self._order), timer))
            self._wake.notify()
        return timer

    def call_later(self, delay: float, callback: Callable[[], None]) -> Timer:
        return self.call_at(self.now() + max(0.0, delay), callback)

    def call_soon(self, callback: Callable[[], None]) -> Timer:
        return self.call_at(float("-inf"), callback)

    def stop(self) -> None:
        """Make :meth:`run` return after the callback it is running (thread safe)."""
        with self._wake:
            self._stopped = True
            self._wake.notify()

    def run(self, until: float | None = None, stop_when: Callable[[], bool] | None = None) -> float:
        """Run callbacks as they fall due until ``until`` (absolute time), ``stop_when()`` or
        :meth:`stop`; returns the time reached. An empty queue waits for more."""
        self._stopped = False
        while not (stop_when and stop_when()):
            timer = self._next(until)
            if timer is None:
                break
            timer.callback()
        return self.now()

    def _next(self, until: float | None) -> Timer | None:
        """The next callback once it is due; None when the run should end."""
        with self._wake:
            while not self._stopped:
                while self._queue and self._queue[0][2].cancelled:
                    heapq.heappop(self._queue)
                now = self.now()
                if until is not None and now >= until:
                    return None
                if self._queue and self._queue[0][0] <= now:
                    return heapq.heappop(self._queue)[2]
                due = self._queue[0][0] if self._queue else None
                wait = [t for t in (until, due) if t is not None]
                self._wake.wait(min(wait) - now if wait else None)
            return None
