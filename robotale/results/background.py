"""Preparing a stored log's pages without making anyone wait for it.

``robotale ingest`` ends when the log is stored; what the dashboard shows first of it (the
findings, the perspectives, the class graph beside them, the runs and the first timeline,
:func:`~robotale.results.findings.prepare`) is computed afterwards by a process of its own,
started here and detached from the command, at a lower priority. A page visited before it
is done computes what it shows itself, as it does for a log nobody prepared: both write the
same result whole, so whichever finishes first is kept.

While it works it keeps the file :data:`PROGRESS` in the build's results folder up to date
(steps done, steps in all), and when it ends it leaves the file :data:`DONE` there, with how
long it took, so a script, a test or a page can wait for it. A page visited before any
preparation ran (``robotale ingest --pages visit``, a dashboard restarted meanwhile) starts one
in the dashboard (:class:`Preparations`) and shows its progress until it is done.

    python -m robotale.results.background LOG
"""

from __future__ import annotations

import contextlib
import json
import os
import subprocess
import sys
import threading
import time
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from neo4j import Driver

from robotale.ekg.columnar import results_folder
from robotale.files import write_file
from robotale.results.findings import PAGE_STEPS, prepare
from robotale.results.logdata import LogData, current_build

#: the file a finished preparation leaves in the build's results folder
DONE = "prepared.done"
#: the file a preparation keeps up to date while it works: ``{"done": N, "total": M, ...}``
PROGRESS = "prepared.progress"
#: a progress file not written for this long belongs to a preparation that died
STALE_SECONDS = 120.0
#: how much lower the preparing process runs than the command that started it
NICENESS = 10
#: the longest a question about a preparation waits for it to go on (seconds)
LONGEST_WAIT = 5.0
#: how often a waiting question looks at the preparation's progress (seconds)
LOOK_EVERY = 0.05


def start(name: str) -> subprocess.Popen[bytes]:
    """Start preparing the pages of the stored log ``name`` in a process of its own that
    outlives the caller (same Neo4j and robotale home, from the environment)."""
    return subprocess.Popen(
        [sys.executable, "-m", "robotale.results.background", name],
        stdin=subprocess.DEVNULL,
        stdout=subprocess.DEVNULL,
        stderr=subprocess.DEVNULL,
        start_new_session=True,  # a Ctrl-C meant for the command does not stop it
        close_fds=True,
    )


def prepare_now(
    driver: Driver, name: str, logs: LogData | None = None, first: Sequence[str] = ()
) -> float:
    """Prepare the pages of ``name`` here (with the logs ``logs`` keeps in memory, if given;
    the steps ``first`` first); returns the seconds it took, keeps :data:`PROGRESS` and
    leaves :data:`DONE` in the build's results folder."""
    started = time.perf_counter()
    build = current_build(driver, name)
    folder = results_folder(build)

    steps: list[str] = []

    def progress(done: int, total: int, step: str) -> None:
        steps.extend([step] if step else [])
        if build.complete:  # a build being written keeps no results
            known = {"done": done, "total": total, "steps": steps}
            write_file(folder / PROGRESS, json.dumps(known))

    progress(0, 0, "")
    prepare(driver, logs or LogData(), name, progress, first)
    seconds = time.perf_counter() - started
    if current_build(driver, name).complete:
        write_file(folder / DONE, json.dumps({"seconds": seconds}))
    return seconds


@dataclass(frozen=True)
class Preparation:
    """How far the preparation of a log's pages is: ``ready`` when a page has nothing to wait
    for, else ``done`` of ``total`` steps (0 of 0: just started), the last one ``step``."""

    ready: bool
    done: int = 0
    total: int = 0
    step: str = ""

    def to_dict(self) -> dict[str, Any]:
        return {"ready": self.ready, "done": self.done, "total": self.total, "step": self.step}


class Preparations:
    """The preparations one dashboard runs for pages visited before their log was prepared:
    at most one per build of a log, in a thread, with the dashboard's own logs in memory."""

    def __init__(self) -> None:
        self._lock = threading.Lock()
        self._running: dict[tuple[str, str], threading.Thread] = {}

    def status(
        self, driver: Driver, logs: LogData, name: str, page: str = "", wait: float = 0.0
    ) -> Preparation:
        """How far the preparation of ``name``'s pages is, ready when the steps the page
        ``page`` shows are done (a page not named: all of them); starts a preparation when
        none is done or under way (here or in another process, such as ``robotale
        ingest``'s). With ``wait`` (seconds, at most :data:`LONGEST_WAIT`), an answer that is
        not ready waits until it is, or until a step is done, or that long: a page waiting
        for its results hears of them at once instead of at its next question."""
        found = self._status(driver, logs, name, page)
        deadline = time.monotonic() + min(max(wait, 0.0), LONGEST_WAIT)
        while not found.ready and time.monotonic() < deadline:
            time.sleep(LOOK_EVERY)
            later = self._status(driver, logs, name, page)
            if later != found:
                return later
        return found

    def _status(self, driver: Driver, logs: LogData, name: str, page: str) -> Preparation:
        build = current_build(driver, name)
        if not build.complete:  # being written: its pages compute what they show
            return Preparation(ready=True)
        folder = results_folder(build)
        if (folder / DONE).is_file():
            return Preparation(ready=True)
        with self._lock:
            running = self._running.get((name, build.key))
            if running is not None and not running.is_alive():
                return Preparation(ready=True)  # ours ended without DONE: the pages say why
            if running is None and not _fresh(folder / PROGRESS):  # none under way anywhere
                # the steps of the page that asked first: it shows them as soon as they are kept
                first = PAGE_STEPS.get(page, ())
                running = threading.Thread(
                    target=self._prepare,
                    args=((name, build.key), driver, logs, first),
                    daemon=True,
                )
                self._running[(name, build.key)] = running
                running.start()
        return _progress(folder / PROGRESS, PAGE_STEPS.get(page))

    def wait(self) -> None:
        """Return once the preparations this dashboard runs are done: what a measurement of
        one page waits for before the next, so neither pays for the other's preparation."""
        with self._lock:
            running = list(self._running.values())
        for thread in running:
            thread.join()

    def _prepare(
        self, key: tuple[str, str], driver: Driver, logs: LogData, first: Sequence[str]
    ) -> None:
        """:func:`prepare_now` in a thread. A failure is not raised: its thread stays on
        record, so the pages compute what they show (and say why) instead of trying again."""
        try:
            prepare_now(driver, key[0], logs, first)
        except Exception:  # whatever failed, the pages report it themselves
            return
        with self._lock:  # done: a later visit starts another only if the results went
            self._running.pop(key, None)


def _fresh(path: Path) -> bool:
    """Whether a preparation wrote ``path`` lately (it is working still)."""
    try:
        return time.time() - path.stat().st_mtime < STALE_SECONDS
    except OSError:
        return False


def _progress(path: Path, needed: Sequence[str] | None) -> Preparation:
    """The progress ``path`` holds; ready when the steps ``needed`` are done."""
    try:
        known = json.loads(path.read_text(encoding="utf-8"))
        done, total, steps = int(known["done"]), int(known["total"]), list(known["steps"])
    except (OSError, ValueError, KeyError, TypeError):  # not written yet, or being written
        return Preparation(ready=False)
    ready = needed is not None and set(needed) <= set(steps)
    return Preparation(ready, done, total, steps[-1] if steps else "")


def done_file(driver: Driver, name: str) -> Path:
    """Where the preparation of the current build of ``name`` says it is done."""
    return results_folder(current_build(driver, name)) / DONE


def main(argv: list[str]) -> int:
    # function-level: the connection settings are read only when the process runs
    from robotale.ekg.connection import session_driver

    if len(argv) != 1:
        print("usage: python -m robotale.results.background LOG", file=sys.stderr)
        return 2
    with contextlib.suppress(OSError):  # not allowed here: prepare at the same priority
        os.nice(NICENESS)
    with session_driver() as driver:
        prepare_now(driver, argv[0])
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
