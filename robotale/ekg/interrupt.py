"""Ctrl-C while a log is written: finish the transaction under way, then stop.

A KeyboardInterrupt raised inside the Neo4j driver while it reads from its socket can leave
the connection unusable, and then what was written cannot be removed again. While
:class:`DeferredInterrupt` is active, Ctrl-C only takes note; :meth:`check`, called between
transactions, raises the KeyboardInterrupt at a point where the driver is idle. A second
Ctrl-C interrupts at once.
"""

from __future__ import annotations

import signal
import threading
from types import FrameType
from typing import Any


class DeferredInterrupt:
    def __init__(self) -> None:
        self.pending = False
        self._previous: Any = None

    def __enter__(self) -> DeferredInterrupt:
        if threading.current_thread() is threading.main_thread():
            self._previous = signal.signal(signal.SIGINT, self._note)
        return self

    def __exit__(self, *exc: object) -> None:
        if self._previous is not None:
            signal.signal(signal.SIGINT, self._previous)
            self._previous = None

    def check(self) -> None:
        """Raise the KeyboardInterrupt that Ctrl-C asked for, if it did."""
        if self.pending:
            raise KeyboardInterrupt

    def _note(self, signum: int, frame: FrameType | None) -> None:
        self.pending = True
        signal.signal(signal.SIGINT, self._previous)
