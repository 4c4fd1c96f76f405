"""A few long-lived worker processes that run the console's queries, each with its memory
capped and each answering several requests at once on threads
(``python -m robotale.ekg.readonly <megabytes> <threads>``).

Starting a Python process with the Neo4j driver per request took seconds on a busy machine;
a worker starts once and keeps its connection. One request per worker made twenty clients
queue behind four processes that mostly waited for Neo4j, so a worker takes up to
``threads`` requests at once: the caps that matter are per transaction (Neo4j's time and
memory limits, the watchdog) and per request (rows and bytes of the answer), and the
process boundary keeps the answers' Python-side memory out of the dashboard.

A request goes to the least busy worker with a free thread (or starts one, up to ``size``),
sends one JSON line and waits for the line with its ``id``. A request that does not answer in
time, or whose answer ran out of memory, ends its worker as before (its thread may still be
decoding an enormous answer, which only ending the process stops; what Neo4j still runs for
it is the watchdog's, :mod:`robotale.webapp.console_watchdog`); the other requests that worker
held are asked again once on another worker (they only read, so asking twice is harmless).
"""

from __future__ import annotations

import json
import logging
import os
import queue
import subprocess
import sys
import tempfile
import threading
import time
from dataclasses import dataclass, field
from typing import IO, Any

from robotale.ekg import readonly

log = logging.getLogger(__name__)
#: seconds a worker may take to start (import, connect nothing yet) on a busy machine
STARTUP = 120.0
#: what a worker says once it is ready for requests
READY = b"ready\n"
#: requests one worker answers at once
THREADS = 8


class NoAnswer(Exception):
    """The worker did not answer within the time it was given."""


@dataclass
class Died(Exception):
    """The worker ended without answering: ``memory`` when its cap (or the kernel) ended it."""

    memory: bool
    last_line: str
    #: ended because of another request it held (a timeout, a MemoryError): worth asking again
    innocent: bool = False


@dataclass
class _Waiting:
    """One request sent to a worker, until its reply (or the worker's end) comes."""

    done: threading.Event = field(default_factory=threading.Event)
    reply: dict[str, Any] | None = None
    died: Died | None = None


class Worker:
    """One capped process answering up to ``threads`` requests at once."""

    def __init__(self, megabytes: int, threads: int, changed: threading.Condition) -> None:
        self.threads = threads
        #: requests sent and not answered yet (given-up ones included: they hold a thread)
        self.busy = 0
        #: a request it held timed out or ran out of memory: it takes no more and is ended
        self.retiring = False
        self._changed = changed  # the pool's: notified when a thread frees or the worker ends
        self._waiting: dict[str, _Waiting] = {}
        self._write = threading.Lock()
        self._ended = False
        self._start_stalled = False
        # stderr goes to a file: a pipe nobody reads could fill up and stall the worker
        self._stderr = tempfile.TemporaryFile()  # noqa: SIM115 (closed with the worker)
        self.process = subprocess.Popen(
            [sys.executable, "-m", readonly.__name__, str(megabytes), str(threads)],
            stdin=subprocess.PIPE,
            stdout=subprocess.PIPE,
            stderr=self._stderr,
            # one malloc arena: each thread's own would reserve 64 MB of the capped space
            env={**os.environ, "MALLOC_ARENA_MAX": "1"},
        )
        assert self.process.stdout is not None
        # Its start (Python, the driver) is not the query's time: wait for it apart.
        if not self._started(self.process.stdout):
            self.kill()
            raise self._died()
        threading.Thread(target=self._read, args=(self.process.stdout,), daemon=True).start()

    def _started(self, stdout: IO[bytes]) -> bool:
        timer = threading.Timer(STARTUP, self._stall)  # a stalled start ends the read
        timer.start()
        try:
            return stdout.readline() == READY
        finally:
            timer.cancel()

    def _stall(self) -> None:
        self._start_stalled = True
        self.process.kill()

    def ask(self, request: dict[str, Any], timeout: float) -> dict[str, Any]:
        """The worker's reply to ``request`` (which the caller counted in :attr:`busy`);
        :class:`NoAnswer` after ``timeout`` seconds, :class:`Died` when the worker ended."""
        assert self.process.stdin is not None
        waiting = _Waiting()
        with self._changed:
            if self._ended:
                raise self._died()
            self._waiting[request["id"]] = waiting
        try:
            with self._write:
                self.process.stdin.write(json.dumps(request).encode() + b"\n")
                self.process.stdin.flush()
        except (BrokenPipeError, ValueError):
            pass  # the worker ended: the reader fails what it held, this request included
        if not waiting.done.wait(timeout):
            with self._changed:
                self._waiting.pop(request["id"], None)
                self.retiring = True
            self.kill()
            raise NoAnswer()
        if waiting.died is not None:
            raise waiting.died
        assert waiting.reply is not None
        return waiting.reply

    def _read(self, stdout: IO[bytes]) -> None:
        for line in stdout:
            reply = json.loads(line)
            with self._changed:
                waiting = self._waiting.pop(reply.get("id", ""), None)
                self.busy -= 1
                memory = reply.get("kind") == "MemoryError"
                self.retiring = self.retiring or memory
                self._changed.notify_all()
            if waiting is not None:
                waiting.reply = reply
                waiting.done.set()
            if memory:  # what the failed request left behind is not worth keeping
                self.kill()
        died = self._died()
        with self._changed:
            self._ended = True
            held, self._waiting = self._waiting, {}
            self._changed.notify_all()
        if self.retiring:
            died = Died(memory=False, last_line=died.last_line, innocent=True)
        for waiting in held.values():
            waiting.died = died
            waiting.done.set()

    def _died(self) -> Died:
        code = self.process.wait()
        if self._start_stalled:
            return Died(memory=False, last_line=f"it did not start within {STARTUP:.0f} s")
        self._stderr.seek(0)
        text = self._stderr.read().decode(errors="replace").strip()
        last = (text.splitlines() or [f"exit status {code}"])[-1]
        return Died(memory=code < 0 or "MemoryError" in text, last_line=last[:300])

    def usable(self) -> bool:
        return not self._ended and not self.retiring and self.busy < self.threads

    def ended(self) -> bool:
        return self._ended

    def kill(self) -> None:
        if self.process.poll() is None:
            self.process.kill()
        self.process.wait()


class Pool:
    """At most ``size`` workers of ``threads`` threads each; requests beyond them wait for a
    free thread."""

    def __init__(self, size: int, megabytes: int, threads: int = THREADS) -> None:
        self.size = size
        self.megabytes = megabytes
        self.threads = threads
        self._workers: list[Worker] = []
        self._starting = 0
        self._changed = threading.Condition()

    @property
    def capacity(self) -> int:
        """Requests the pool answers at once."""
        return self.size * self.threads

    def ask(self, request: dict[str, Any], timeout: float, wait: float) -> dict[str, Any]:
        """Run ``request`` on a worker: :class:`NoAnswer`, :class:`Died` as
        :meth:`Worker.ask`; :class:`queue.Empty` when no thread was free within ``wait``."""
        started = time.monotonic()
        worker = self._take(wait)
        waited = time.monotonic() - started
        try:
            reply = worker.ask(request, timeout)
        except Died as died:
            if not died.innocent:
                raise
            reply = self._take(max(0.0, started + wait - time.monotonic())).ask(request, timeout)
        # The parts of a request's time, for whoever runs the dashboard (DEBUG): waiting for
        # a thread, the worker's own time (plan check, query, values to JSON), and the rest
        # (the pipes, decoding the reply).
        total = time.monotonic() - started
        log.debug(
            "console request %s: waited %.3f s, worker %.3f s, pipes %.3f s, total %.3f s",
            request.get("id"),
            waited,
            reply.get("seconds", 0.0),
            total - waited - reply.get("seconds", 0.0),
            total,
        )
        return reply

    def _take(self, wait: float) -> Worker:
        deadline = time.monotonic() + wait
        with self._changed:
            while True:
                self._workers = [worker for worker in self._workers if not worker.ended()]
                usable = [worker for worker in self._workers if worker.usable()]
                if usable:
                    worker = min(usable, key=lambda each: each.busy)
                    worker.busy += 1
                    return worker
                if len(self._workers) + self._starting < self.size:
                    self._starting += 1
                    break
                remaining = deadline - time.monotonic()
                if remaining <= 0:
                    raise queue.Empty
                self._changed.wait(remaining)
        try:
            worker = Worker(self.megabytes, self.threads, self._changed)
        finally:
            with self._changed:
                self._starting -= 1
                self._changed.notify_all()
        with self._changed:
            worker.busy += 1
            self._workers.append(worker)
        return worker

    def close(self) -> None:
        with self._changed:
            workers, self._workers = self._workers, []
        for worker in workers:
            worker.kill()
