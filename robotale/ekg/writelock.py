"""One writer per log name: a lock node in Neo4j, :func:`log_write_lock`.

Before anything of a log is written (an ingest, a rebuild, a delete), the writer creates a
``LogLock`` node for the log's name in a transaction of its own. A uniqueness constraint makes
a second writer's attempt fail at once, so two ingests of one name started together cannot mix
their nodes or undo each other's work. The lock records the writer's host, pid and the pid's
start time: a lock whose writer died (killed, or its Neo4j went away so it could not give the
lock back) is recognised as stale and taken over by the next writer.
"""

from __future__ import annotations

import os
import socket
import uuid
from collections.abc import Iterator
from contextlib import contextmanager, suppress
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from neo4j import Driver, RoutingControl
from neo4j.exceptions import ConstraintError, DriverError, Neo4jError

from robotale.ekg.connection import database
from robotale.errors import InputError
from robotale.queries import cypher

# The runs of this process that hold a lock right now.
_ACTIVE: set[str] = set()


class LogBusy(InputError):
    """Another live writer holds the log's lock."""


@dataclass(frozen=True)
class Holder:
    """Who holds the lock of one log name."""

    run: str
    host: str
    pid: int
    pid_start: str
    started: str

    @classmethod
    def of(cls, row: dict[str, Any]) -> Holder:
        return cls(
            str(row["run"]),
            str(row["host"]),
            int(row["pid"]),
            str(row["pidStart"]),
            str(row["started"]),
        )

    def alive(self) -> bool:
        """False when the writer certainly ended: it ran here and its process is gone.

        A writer on another host cannot be checked from here and counts as alive.
        """
        if self.host != socket.gethostname():
            return True
        if self.pid == os.getpid():  # a long-lived process (the dashboard) knows its runs
            return self.run in _ACTIVE
        return _process_start(self.pid) == self.pid_start

    def describe(self) -> str:
        return f"pid {self.pid} on {self.host}, since {self.started}"


def holders(driver: Driver) -> dict[str, Holder]:
    """Every lock by the name of the log it guards (read as ``logs list`` reads)."""
    records, _, _ = driver.execute_query(
        cypher("ekg_lock_holders"), database_=database(), routing_=RoutingControl.READ
    )
    return {str(r["name"]): Holder.of(r.data()) for r in records}


def holder(driver: Driver, name: str) -> Holder | None:
    records, _, _ = driver.execute_query(cypher("ekg_lock_holder"), name=name, database_=database())
    return Holder.of(records[0].data()) if records else None


@contextmanager
def log_write_lock(driver: Driver, name: str, doing: str = "writing") -> Iterator[str]:
    """Hold the write lock of ``name`` while the block runs; yields this run's id.

    A :class:`LogBusy` naming the other writer if a live one holds it. The lock is given back
    when the block ends, also on failure; if Neo4j is gone by then, the lock stays and is
    recognised as stale later (its writer has ended).
    """
    run = take(driver, name, doing)
    try:
        yield run
    finally:
        release(driver, name, run)


def take(driver: Driver, name: str, doing: str = "writing") -> str:
    """Take the write lock of ``name`` (as :func:`log_write_lock` does); returns the run's
    id, which :func:`release` needs: for a writer whose driver changes meanwhile."""
    return _take(driver, name, doing)


def release(driver: Driver, name: str, run: str) -> None:
    """Give back the lock of ``name`` that ``run`` holds, if it still does."""
    _ACTIVE.discard(run)
    # If Neo4j is gone the lock stays; its run is no longer active, so it counts as stale.
    with suppress(Neo4jError, DriverError, OSError), driver.session(database=database()) as s:
        # One attempt: managed retries against a server that is gone take half a minute.
        s.run(cypher("ekg_lock_release"), name=name, run=run).consume()


def _take(driver: Driver, name: str, doing: str) -> str:
    run = uuid.uuid4().hex
    for _ in range(2):  # the second time after removing a stale lock
        try:
            driver.execute_query(
                cypher("ekg_lock_take"),
                name=name,
                run=run,
                host=socket.gethostname(),
                pid=os.getpid(),
                pidStart=_process_start(os.getpid()),
                database_=database(),
            )
            _ACTIVE.add(run)
            return run
        except ConstraintError:
            other = holder(driver, name)
            if other is not None and other.alive():
                raise LogBusy(
                    f"The log {name!r} is being written by another robotale "
                    f"({other.describe()}); {doing} it now is refused: wait until that "
                    "one has finished."
                ) from None
            if other is not None:
                driver.execute_query(
                    cypher("ekg_lock_release"), name=name, run=other.run, database_=database()
                )
    raise LogBusy(f"The log {name!r} is being written by another robotale; try again.")


def _process_start(pid: int) -> str:
    """The start time of ``pid`` in clock ticks since boot ("" if there is no such process):
    with the pid it names one process, even after the pid has been reused."""
    try:
        stat = Path(f"/proc/{pid}/stat").read_text()
    except OSError:
        return ""
    fields = stat.rsplit(")", 1)[-1].split()
    return "" if fields[0] == "Z" else fields[19]
