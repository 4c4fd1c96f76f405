"""Preparing a stored log's pages without making anyone wait for it.

``robotale ingest`` ends when the log is stored; what the dashboard shows first of it (the
findings, the perspectives, the class graph beside them, the runs and the first timeline,
:func:`~robotale.results.findings.prepare`) is computed afterwards by a process of its own,
started here and detached from the command, at a lower priority. A page visited before it
is done computes what it shows itself, as it does for a log nobody prepared: both write the
same result whole, so whichever finishes first is kept.

When the preparation ends it leaves the file :data:`DONE` in the build's results folder, with
how long it took, so a script (or a test) can wait for it.

    python -m robotale.results.background LOG
"""

from __future__ import annotations

import contextlib
import json
import os
import subprocess
import sys
import time
from pathlib import Path

from neo4j import Driver

from robotale.ekg.columnar import results_folder
from robotale.files import write_file
from robotale.results.findings import prepare
from robotale.results.logdata import LogData, current_build

#: the file a finished preparation leaves in the build's results folder
DONE = "prepared.done"
#: how much lower the preparing process runs than the command that started it
NICENESS = 10


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


def prepare_now(driver: Driver, name: str) -> float:
    """Prepare the pages of ``name`` here; returns the seconds it took and leaves
    :data:`DONE` in the build's results folder."""
    started = time.perf_counter()
    prepare(driver, LogData(), name)
    seconds = time.perf_counter() - started
    build = current_build(driver, name)
    if build.complete:
        write_file(results_folder(build) / DONE, json.dumps({"seconds": seconds}))
    return seconds


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
