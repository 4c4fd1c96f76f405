"""The event logs stored in Neo4j: list them, read one log, delete one.

Every read of one stored log goes through here, each query a file of ``cypher/`` run in a read
transaction (a cluster's followers answer it; see docs/scale.md), and a name
under which nothing is stored raises :class:`~robotale.errors.LogNotFound` (whose ``hint``
lets each caller say where logs come from: the command line, the dashboard's Logs page).
"""

from __future__ import annotations

from collections.abc import Callable
from contextvars import ContextVar, Token
from typing import Any, TypeVar

from neo4j import READ_ACCESS, Driver

from robotale.ekg.connection import database, read_rows
from robotale.ekg.writelock import Holder, holders, log_write_lock
from robotale.errors import LogNotFound
from robotale.queries import cypher, statements

# The status of a log whose ingest ended before it was complete.
FAILED = "failed"
# A live log (robotale.ekg.growing) while its monitor grows it, and once that monitor ended
# without completing it (killed): what it holds is consistent, but the run went on unheard.
LIVE, INTERRUPTED = "live", "interrupted"

#: the query of a log's build (:func:`log_build_row`; parameter ``$log``): for a writer that
#: reads it in the transaction that takes the log's lock
BUILD_QUERY = "ekg_log_build"
#: within a look (:func:`start_look`): what each Log node said, by what was asked and log name
_LOOK: ContextVar[dict[tuple[str, str], Any] | None] = ContextVar("log_look", default=None)
_Read = TypeVar("_Read")


def start_look() -> Token[dict[tuple[str, str], Any] | None]:
    """From now until :func:`end_look`, in this context, each log's Log node is read once (its
    build and its description): one answer of the dashboard asks for them a dozen times, and
    each is a round trip to Neo4j. For what only reads and shows one state of a log."""
    return _LOOK.set({})


def end_look(token: Token[dict[tuple[str, str], Any] | None]) -> None:
    try:
        _LOOK.reset(token)
    except ValueError:  # ended in another context than it started in: nothing kept here
        _LOOK.set(None)


def _looked(what: str, name: str, read: Callable[[], _Read]) -> _Read:
    """``read()``, once per look."""
    seen = _LOOK.get()
    if seen is None:
        return read()
    if (what, name) not in seen:
        seen[(what, name)] = read()
    found: _Read = seen[(what, name)]
    return found


def list_logs(driver: Driver) -> list[dict[str, Any]]:
    """Every stored log as its Log node describes it, by name (see :func:`_with_truth`)."""
    locks = holders(driver)
    return [_with_truth(driver, row, locks) for row in _rows(driver, "ekg_list_logs", log=None)]


def log_info(driver: Driver, name: str, hint: str | None = None) -> dict[str, Any]:
    """What the Log node of ``name`` records: ``status``, ``events``, ``source``,
    ``entityTypes``, ``classTypes``, ``created`` (text) and the event ``properties``."""
    found = _looked("info", name, lambda: _info(driver, name))
    if found is None:
        raise LogNotFound(name, hint)
    return dict(found)


def _info(driver: Driver, name: str) -> dict[str, Any] | None:
    rows = _rows(driver, "ekg_log_info", log=name)
    return _with_truth(driver, rows[0], holders(driver)) if rows else None


def _with_truth(driver: Driver, row: dict[str, Any], locks: dict[str, Holder]) -> dict[str, Any]:
    """A log still marked ``building`` whose writer has ended (killed, or its Neo4j went away
    before it could finish or undo) is ``failed``; such logs, and those being built, get the
    number of events stored so far rather than the count a finished build records."""
    row = dict(row)
    run = row.pop("run", None)
    if row["status"] not in ("building", LIVE):
        return row
    # A rebuild writes under a temporary name while the lock guards the log's own name:
    # the writer is the lock of the same run.
    writer = next((lock for lock in locks.values() if lock.run == run), None)
    alive = writer is not None and writer.alive()
    if row["status"] == LIVE:
        return row | {"status": LIVE if alive else INTERRUPTED}
    status = "building" if alive else FAILED
    return row | {"status": status, "events": stored_events(driver, row["name"])}


def log_run(driver: Driver, name: str) -> str | None:
    """The id of the run that wrote the Log node of ``name`` (None without one)."""
    rows = _rows(driver, "ekg_log_run", log=name)
    return rows[0]["run"] if rows else None


def log_build_row(driver: Driver, name: str, hint: str | None = None) -> dict[str, Any]:
    """What the Log node of ``name`` records of its current build (``status``, ``created``,
    ``run``, ``appended``, ``properties``, ``columns``), for its columnar copy."""
    rows = _looked("build", name, lambda: _rows(driver, BUILD_QUERY, log=name))
    if not rows:
        raise LogNotFound(name, hint)
    return dict(rows[0])


def log_summary(driver: Driver, name: str, hint: str | None = None) -> dict[str, Any]:
    """:func:`log_info` plus counts taken from the graph.

    ``counts`` maps ``"events"``, ``"entities:robot"``, ``"DF:robot"``,
    ``"DF_C:activity / robot"`` ... to numbers.
    """
    info = log_info(driver, name, hint)
    counts = {
        r["what"] if r["type"] is None else f"{r['what']}:{r['type']}": r["count"]
        for r in _rows(driver, "ekg_log_counts", log=name)
        if r["count"]
    }
    return info | {"counts": counts}


def log_exists(driver: Driver, name: str) -> bool:
    """Whether anything (a Log node or events) is stored under ``name``."""
    return bool(_rows(driver, "ekg_log_exists", log=name)[0]["exists"])


def require_log(driver: Driver, name: str, hint: str | None = None) -> None:
    """A :class:`LogNotFound` unless something is stored under ``name``."""
    if not log_exists(driver, name):
        raise LogNotFound(name, hint)


def log_values(driver: Driver, name: str) -> dict[str, Any]:
    """The distinct ``case``, ``robot``, ``robot_type`` and ``activity`` values of the log's
    events (lists) and their number, ``events``."""
    return _rows(driver, "ekg_log_values", log=name)[0]


def log_robots(driver: Driver, name: str) -> list[str]:
    """The robots the log's events name."""
    return [str(robot) for robot in _rows(driver, "ekg_log_robots", log=name)[0]["robots"]]


def stored_events(driver: Driver, name: str) -> int:
    """How many events of ``name`` are stored so far (also while it is being built)."""
    return int(_rows(driver, "ekg_log_event_count", log=name)[0]["events"])


def delete_log(driver: Driver, name: str) -> None:
    """Remove a log and everything that belongs to it (nothing happens if there is none)."""
    with driver.session(database=database()) as session:
        for statement in statements("ekg_delete_log"):
            session.run(statement, log=name).consume()


def delete_log_locked(driver: Driver, name: str) -> None:
    """:func:`delete_log` under the log's write lock: refused while a live writer builds it;
    a lock left by a writer that died is taken over."""
    with log_write_lock(driver, name, "deleting"):
        delete_log(driver, name)


def graph_counts(driver: Driver) -> dict[str, int]:
    """``{"node:Event": n, "relationship:DF": m, ...}`` for the whole database."""
    with driver.session(database=database(), default_access_mode=READ_ACCESS) as session:
        result = session.run(cypher("ekg_graph_counts"))
        return {f"{r['kind']}:{r['name']}": r["count"] for r in result if r["count"]}


def _rows(driver: Driver, query: str, **parameters: Any) -> list[dict[str, Any]]:
    return read_rows(driver, cypher(query), **parameters)
