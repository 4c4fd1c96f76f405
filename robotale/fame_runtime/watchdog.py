"""The time limit of Python scripts: one watchdog thread for the whole process.

A Python script runs in its engine's thread, so nothing but another thread can stop one that
never returns. A timer per script costs microseconds each; instead the engine writes a stamp
before each script (``Watch.running``: the script's node and thread) and clears it after,
and a single daemon thread, started with the first watch, looks at the stamps a few times a
second. A stamp it sees unchanged for longer than the limit, in CPU time of the engine's
thread where the platform can read another thread's CPU clock (else wall time), gets an
asynchronous :class:`ScriptTimeout` raised in that thread, which the engine turns into its
model error. The limit is therefore met within one period of the watchdog (``TIME_LIMIT /
4``, at most 0.25 s), and a script stuck inside one long C call (a ``time.sleep``, a huge
``sum``) is stopped only when that call returns.
"""

from __future__ import annotations

import ctypes
import threading
import time
import weakref
from typing import Any

#: seconds of CPU time one Python script may take (the name of the JavaScript limit too)
TIME_LIMIT = 2.0

_cpu_clock = getattr(time, "pthread_getcpuclockid", None)
#: what the limit is measured in on this platform
MEASURE = "CPU time" if _cpu_clock is not None else "wall time"


class ScriptTimeout(BaseException):
    """Raised in an engine's thread inside a script that ran past its limit. A
    BaseException, so a script's ``except Exception`` does not swallow it."""


class Watch:
    """One engine's stamp: ``running`` is ``(node, thread id)`` while a script runs, else
    None. The engine writes it without a lock (two attribute writes per script); the rare
    race with a firing watchdog is settled by :meth:`settle` under ``lock``."""

    __slots__ = ("__weakref__", "fired", "limit", "lock", "running")

    def __init__(self, limit: float) -> None:
        self.running: tuple[Any, int] | None = None
        self.fired = False  # the watchdog decided this script is over its limit
        self.limit = limit
        self.lock = threading.Lock()

    def settle(self) -> None:
        """After a script the watchdog fired on (``fired``, its stamp already cleared): take
        back an exception not yet delivered and raise it here, so it never lands in the
        engine's own code. The script did run past its limit, delivered or not."""
        with self.lock:
            self.fired = False
            here = threading.get_ident()
            ctypes.pythonapi.PyThreadState_SetAsyncExc(ctypes.c_ulong(here), None)
        raise ScriptTimeout


class _Watchdog(threading.Thread):
    def __init__(self) -> None:
        super().__init__(name="robotale-script-watchdog", daemon=True)
        self.watches: weakref.WeakSet[Watch] = weakref.WeakSet()
        self.period = 0.25
        self._seen: dict[int, tuple[tuple[Any, int], float]] = {}  # id(watch): stamp, since

    def run(self) -> None:
        while True:
            time.sleep(self.period)
            for watch in list(self.watches):
                self._look(watch)

    def _look(self, watch: Watch) -> None:
        stamp = watch.running
        key = id(watch)
        if stamp is None:
            self._seen.pop(key, None)
            return
        now = _now(stamp[1])
        seen = self._seen.get(key)
        if seen is None or seen[0] is not stamp:  # a new script: held by identity
            self._seen[key] = (stamp, now)
            return
        if now - seen[1] >= watch.limit:
            self._fire(watch, stamp)
            # a script that swallowed it (a bare except) is fired on again a limit later
            self._seen[key] = (stamp, now)

    @staticmethod
    def _fire(watch: Watch, stamp: tuple[Any, int]) -> None:
        with watch.lock:
            # fired first: an engine that clears its stamp from now on settles; one that
            # cleared it before is not fired on, and its next script must not settle
            watch.fired = True
            if watch.running is stamp:
                ctypes.pythonapi.PyThreadState_SetAsyncExc(
                    ctypes.c_ulong(stamp[1]), ctypes.py_object(ScriptTimeout)
                )
            else:
                watch.fired = False


def _now(thread: int) -> float:
    """The CPU time of ``thread``, or the wall clock where it cannot be read."""
    if _cpu_clock is not None:
        try:
            return time.clock_gettime(_cpu_clock(thread))
        except OSError:  # the thread ended, or the platform refuses
            pass
    return time.monotonic()


_dog: _Watchdog | None = None
_start = threading.Lock()


def watch() -> Watch:
    """A new stamp for one engine, watched against the current ``TIME_LIMIT``."""
    global _dog
    made = Watch(TIME_LIMIT)
    with _start:
        if _dog is None:
            _dog = _Watchdog()
            _dog.start()
        _dog.period = min(_dog.period, max(0.01, TIME_LIMIT / 4))
        _dog.watches.add(made)
    return made
