"""Clocks: the one notion of time that engines, skills, the simulated world and tags share.

:class:`SimClock` is a discrete-event scheduler. Simulated time jumps from one scheduled
callback to the next, so a run goes as fast as the machine allows; ``run(pace=1.0)`` paces it
to wall time for a person watching. Time is seconds since the Unix epoch, so tag stamps are
real datetimes. :class:`WallClock` is real time, for engines that run one per process.

On a simulated clock an engine's own computing takes no time unless the clock carries an
:class:`EngineCost`: then each engine keeps an :class:`EngineTime`, the account of how long
its scripts, conditions and token steps keep it busy, and the work after them waits for the
clock to get there (the world goes on meanwhile).
"""

from __future__ import annotations

import contextlib
import heapq
import itertools
import threading
import time
from collections.abc import Callable, Iterator
from dataclasses import asdict, dataclass
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


class RunningClock(Clock, Protocol):
    """A clock that runs its callbacks itself (both of robotale's do)."""

    def run(
        self, until: float | None = None, stop_when: Callable[[], bool] | None = None
    ) -> float: ...


class SimClock:
    """Simulated time driven by a queue of callbacks.

    Callbacks scheduled for the same instant run in the order they were scheduled, which keeps
    runs deterministic for a seed.
    """

    def __init__(self, start: float = 0.0, *, engine_cost: EngineCost | None = None) -> None:
        self._now = float(start)
        self._queue: list[tuple[float, int, Timer]] = []
        self._order = itertools.count()
        #: what the engines on this clock charge for their work (None: nothing)
        self.engine_cost = engine_cost

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


@dataclass(frozen=True)
class EngineCost:
    """Simulated seconds an engine's work takes: a fixed cost per script task run, condition
    evaluated and token step (deterministic), or, with ``measured`` > 0, the wall time of each
    step (and of each condition evaluated outside a step) times ``measured`` (depends on the
    machine and its load)."""

    script: float = 0.0
    condition: float = 0.0
    step: float = 0.0
    measured: float = 0.0

    @property
    def free(self) -> bool:
        """Nothing is charged: engines run as if computing took no time."""
        return not (self.script or self.condition or self.step or self.measured)

    def as_dict(self) -> dict[str, float]:
        return {key: value for key, value in asdict(self).items() if value}


class EngineTime:
    """One engine's account of its computing time on a simulated clock.

    The engine is busy until :attr:`free_at`; work charged while it is busy queues behind
    (one processor per robot). Measured work may nest (a script inside a step): only the
    outermost piece is timed, so nothing is charged twice.
    """

    def __init__(self, clock: Clock, cost: EngineCost) -> None:
        self.clock, self.cost = clock, cost
        self.free_at = float("-inf")
        self._open = 0  # pieces of work begun and not yet charged
        self._waiting = False  # a callback for when the engine is free is scheduled

    @classmethod
    def of(cls, clock: Clock) -> EngineTime | None:
        """The account for an engine on ``clock``; None when its work costs nothing."""
        cost = getattr(clock, "engine_cost", None)
        return None if cost is None or cost.free else cls(clock, cost)

    def begin(self) -> float:
        self._open += 1
        return time.perf_counter()

    def spent(self, kind: str, began: float) -> bool:
        """Charge a piece of work of ``kind`` (script, condition, step) that began at
        ``began`` (:meth:`begin`); True while the engine is still busy computing."""
        self._open -= 1
        cost = self.cost
        if cost.measured:
            seconds = (time.perf_counter() - began) * cost.measured if not self._open else 0.0
        else:
            seconds = getattr(cost, kind)
        if seconds > 0:
            self.free_at = max(self.free_at, self.clock.now()) + seconds
        return self.busy()

    @contextlib.contextmanager
    def work(self, kind: str) -> Iterator[None]:
        """Charge what the ``with`` block does as work of ``kind``."""
        began = self.begin()
        try:
            yield
        finally:
            self.spent(kind, began)

    def busy(self) -> bool:
        return self.free_at > self.clock.now()

    def wait(self, then: Callable[[], None]) -> bool:
        """False when the engine is free; else ``then`` runs once it is (scheduled once)."""
        if not self.busy():
            return False
        if not self._waiting:
            self._waiting = True
            self.clock.call_at(self.free_at, lambda: self._free(then))
        return True

    def _free(self, then: Callable[[], None]) -> None:
        self._waiting = False
        then()


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
