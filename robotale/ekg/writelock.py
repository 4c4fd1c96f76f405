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
from collections.abc import Iterator, Sequence
from contextlib import contextmanager, suppress
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from neo4j import Driver, ManagedTransaction, RoutingControl
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


@dataclass
class Held:
    """A lock held by :func:`log_write_lock_reading`: what its read queries found, and the
    block's last write if it gave one (:meth:`with_release`)."""

    rows: list[list[dict[str, Any]]]
    closing: tuple[str, dict[str, Any]] | None = None

    def with_release(self, query: str, **parameters: Any) -> None:
        """Write ``query`` in the transaction that gives the lock back, once the block has
        ended without failure: the block's last write costs no commit of its own, and the
        lock is free only once it is written."""
        self.closing = (query, parameters)


@contextmanager
def log_write_lock_reading(
    driver: Driver, name: str, doing: str, queries: Sequence[str], **parameters: Any
) -> Iterator[Held]:
    """:func:`log_write_lock`, the read ``queries`` (with ``parameters``) run in the
    transaction that takes the lock, their rows in the :class:`Held` it yields (one list per
    query). What a writer checks before it writes is then read as of the moment the lock is
    its, without a transaction and round trips of its own (one commit for the lock and the
    checks)."""
    run, rows = _take(driver, name, doing, queries, parameters)
    held = Held(rows)
    try:
        yield held
    except BaseException:
        release(driver, name, run)
        raise
    if held.closing is None:
        release(driver, name, run)
    else:
        _release_after(driver, name, run, *held.closing)


def take(driver: Driver, name: str, doing: str = "writing") -> str:
    """Take the write lock of ``name`` (as :func:`log_write_lock` does); returns the run's
    id, which :func:`release` needs: for a writer whose driver changes meanwhile."""
    return _take(driver, name, doing)[0]


def release(driver: Driver, name: str, run: str) -> None:
    """Give back the lock of ``name`` that ``run`` holds, if it still does."""
    _ACTIVE.discard(run)
    # If Neo4j is gone the lock stays; its run is no longer active, so it counts as stale.
    with suppress(Neo4jError, DriverError, OSError), driver.session(database=database()) as s:
        # One attempt: managed retries against a server that is gone take half a minute.
        s.run(cypher("ekg_lock_release"), name=name, run=run).consume()


def _release_after(
    driver: Driver, name: str, run: str, query: str, parameters: dict[str, Any]
) -> None:
    """Write ``query`` and give back the lock of ``name`` that ``run`` holds, in one
    transaction; if that fails, the lock alone is given back and the failure raised."""
    _ACTIVE.discard(run)
    try:
        with driver.session(database=database()) as session, session.begin_transaction() as tx:
            tx.run(query, parameters).consume()
            tx.run(cypher("ekg_lock_release"), name=name, run=run).consume()
            tx.commit()
    except BaseException:
        release(driver, name, run)
        raise


def _take(
    driver: Driver,
    name: str,
    doing: str,
    queries: Sequence[str] = (),
    parameters: dict[str, Any] | None = None,
) -> tuple[str, list[list[dict[str, Any]]]]:
    """The run's id and the rows of ``queries``, run after the lock's ``CREATE`` in its
    transaction (a writer refused the lock reads nothing)."""
    run = uuid.uuid4().hex
    lock = {
        "name": name,
        "run": run,
        "host": socket.gethostname(),
        "pid": os.getpid(),
        "pidStart": _process_start(os.getpid()),
    }

    def transaction(tx: ManagedTransaction) -> list[list[dict[str, Any]]]:
        tx.run(cypher("ekg_lock_take"), lock).consume()
        return [tx.run(query, parameters or {}).data() for query in queries]

    for _ in range(2):  # the second time after removing a stale lock
        try:
            if queries:
                with driver.session(database=database()) as session:
                    rows = session.execute_write(transaction)
            else:  # one query: the driver's shortest way
                driver.execute_query(cypher("ekg_lock_take"), lock, database_=database())
                rows = []
            _ACTIVE.add(run)
            return run, rows
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
