"""A few long-lived worker processes that run the console's queries, each with its memory
capped (``python -m robotale.ekg.readonly <megabytes>``).

Starting a Python process with the Neo4j driver per request took seconds on a busy machine;
a worker starts once and keeps its connection. A request takes an idle worker (or starts one,
up to ``size``), sends one JSON line and reads one back. A worker that dies (its memory cap
ended it) or does not answer in time is killed and replaced by the next request that needs
one; what Neo4j still runs for it is the watchdog's (:mod:`robotale.webapp.console_watchdog`).
"""

from __future__ import annotations

import json
import os
import queue
import select
import subprocess
import sys
import tempfile
import threading
import time
from dataclasses import dataclass
from typing import Any

from robotale.ekg import readonly

#: seconds a worker may take to start (import, connect nothing yet) on a busy machine
STARTUP = 120.0
#: what a worker says once it is ready for requests
READY = b"ready\n"


class NoAnswer(Exception):
    """The worker did not answer within the time it was given (it has been killed)."""


@dataclass
class Died(Exception):
    """The worker ended without answering: ``memory`` when its cap (or the kernel) ended it."""

    memory: bool
    last_line: str


class Worker:
    """One capped process answering one request at a time."""

    def __init__(self, megabytes: int) -> None:
        # stderr goes to a file: a pipe nobody reads could fill up and stall the worker
        self._stderr = tempfile.TemporaryFile()  # noqa: SIM115 (closed with the worker)
        self.process = subprocess.Popen(
            [sys.executable, "-m", readonly.__name__, str(megabytes)],
            stdin=subprocess.PIPE,
            stdout=subprocess.PIPE,
            stderr=self._stderr,
        )
        # Its start (Python, the driver) is not the query's time: wait for it apart.
        assert self.process.stdout is not None
        line = self._read_line(self.process.stdout.fileno(), time.monotonic() + STARTUP)
        if line != READY:
            self.kill()
            raise self._died()

    def ask(self, request: dict[str, Any], timeout: float) -> dict[str, Any]:
        """The worker's reply to ``request``; :class:`NoAnswer` after ``timeout`` seconds,
        :class:`Died` when it ended."""
        assert self.process.stdin is not None and self.process.stdout is not None
        try:
            self.process.stdin.write(json.dumps(request).encode() + b"\n")
            self.process.stdin.flush()
        except BrokenPipeError:
            raise self._died() from None
        line = self._read_line(self.process.stdout.fileno(), time.monotonic() + timeout)
        if line is None:
            self.kill()
            raise NoAnswer()
        if not line:
            raise self._died()
        return json.loads(line)

    @staticmethod
    def _read_line(fd: int, deadline: float) -> bytes | None:
        # Raw reads with select: a buffered reader could hold a reply select does not see.
        data = b""
        while not data.endswith(b"\n"):
            remaining = deadline - time.monotonic()
            if remaining <= 0:
                return None
            ready, _, _ = select.select([fd], [], [], remaining)
            if not ready:
                return None
            chunk = os.read(fd, 1 << 16)
            if not chunk:
                return b""
            data += chunk
        return data

    def _died(self) -> Died:
        code = self.process.wait()
        if self._stderr.closed:
            return Died(memory=False, last_line=f"it did not start within {STARTUP:.0f} s")
        self._stderr.seek(0)
        text = self._stderr.read().decode(errors="replace").strip()
        self._stderr.close()
        last = (text.splitlines() or [f"exit status {code}"])[-1]
        return Died(memory=code < 0 or "MemoryError" in text, last_line=last[:300])

    def alive(self) -> bool:
        return self.process.poll() is None

    def kill(self) -> None:
        if self.alive():
            self.process.kill()
        self.process.wait()
        self._stderr.close()


class Pool:
    """At most ``size`` workers; requests beyond them wait for one to be free."""

    def __init__(self, size: int, megabytes: int) -> None:
        self.size = size
        self.megabytes = megabytes
        self._idle: queue.LifoQueue[Worker] = queue.LifoQueue()
        self._started = 0
        self._lock = threading.Lock()

    def ask(self, request: dict[str, Any], timeout: float, wait: float) -> dict[str, Any]:
        """Run ``request`` on a worker: :class:`NoAnswer`, :class:`Died` as
        :meth:`Worker.ask`; :class:`queue.Empty` when no worker was free within ``wait``."""
        worker = self._take(wait)
        try:
            reply = worker.ask(request, timeout)
        except (NoAnswer, Died):
            self._forget(worker)
            raise
        except BaseException:
            worker.kill()
            self._forget(worker)
            raise
        if reply.get("kind") == "MemoryError":  # the worker ends itself after that reply
            worker.kill()
            self._forget(worker)
        else:
            self._idle.put(worker)
        return reply

    def _take(self, wait: float) -> Worker:
        try:
            while True:
                worker = self._idle.get_nowait()
                if worker.alive():
                    return worker
                worker.kill()
                self._forget(worker)
        except queue.Empty:
            pass
        deadline = time.monotonic() + wait
        while True:
            with self._lock:
                if self._started < self.size:
                    self._started += 1
                    break
            # a short wait at a time: a worker that died meanwhile frees a place to start one
            step = min(0.5, deadline - time.monotonic())
            if step <= 0:
                raise queue.Empty
            try:
                return self._idle.get(timeout=step)
            except queue.Empty:
                continue
        try:
            return Worker(self.megabytes)
        except BaseException:
            self._forget(None)
            raise

    def _forget(self, worker: Worker | None) -> None:
        with self._lock:
            self._started -= 1

    def close(self) -> None:
        while True:
            try:
                self._idle.get_nowait().kill()
            except queue.Empty:
                return
