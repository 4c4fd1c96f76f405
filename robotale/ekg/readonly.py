"""Run someone else's Cypher so that it can only read the graph, and bound what comes back.

The dashboard's console runs its queries here. Four fences, each enough against what it
covers, checked in this order:

1. The text, before anything is sent: ``LOAD CSV`` (files and URLs), administration commands
   (``SHOW``, ``TERMINATE``, users, databases), ``USE``, ``CALL ... IN TRANSACTIONS`` and
   functions that are not Neo4j's own (a plugin's: APOC's ``apoc.cypher.runFirstColumn``
   would run a ``LOAD CSV`` given to it as a string) are refused, as are integers Neo4j
   cannot hold.
2. The plan (``EXPLAIN``, which runs nothing): Neo4j's own reading of the query decides
   (:mod:`robotale.ekg.plan_check`): every operator must read robotale's database and call
   only allowed procedures and functions, however the text spelled them. The text check
   before it is a fast first filter, never the only one.
3. The transaction: opened in READ access mode with a timeout and without retries, so Neo4j
   refuses every write and a runaway query ends once.
4. The answer: at most ``rows`` rows and ``bytes`` bytes of JSON are kept; the rest is counted
   up to :data:`COUNTED` rows. Every value becomes valid JSON (:func:`cell`).

An answer that passed all four is kept (:mod:`robotale.ekg.answer_cache`) and given again to
the same text, parameters and limits while Neo4j says the database is unchanged.

``python -m robotale.ekg.readonly <megabytes> <threads>`` answers requests (a JSON line each
on stdin, several at once on threads) in a process whose memory is capped, so that a single
enormous value (``RETURN range(1, 1e8)``) costs that process, not the dashboard; the
dashboard keeps a few such workers (:mod:`robotale.webapp.console_pool`).
"""

from __future__ import annotations

import json
import math
import re
import resource
import sys
import threading
import time
from collections.abc import Mapping
from concurrent.futures import ThreadPoolExecutor
from dataclasses import asdict, dataclass
from typing import Any, cast

import neo4j
from neo4j import Driver
from neo4j.exceptions import DriverError, Neo4jError, ServiceUnavailable, SessionExpired
from neo4j.graph import Node, Path, Relationship

from robotale.ekg import answer_cache
from robotale.ekg.answer_cache import AnswerCache
from robotale.ekg.connection import Settings, connect, unreachable_message
from robotale.ekg.connection import database as default_database
from robotale.ekg.plan_check import (
    ALLOWED_PROCEDURES,
    QueryRefused,
    WriteRefused,
    check_plan,
)
from robotale.ekg.plan_check import ONLY_READS as _ONLY_READS
from robotale.errors import InputError, RobotaleError, ServerError
from robotale.queries import code_only, cypher, dotted_calls, split_statements

__all__ = ["ALLOWED_PROCEDURES", "QueryRefused", "WriteRefused", "run_read_only"]

#: the namespaces of Neo4j's own functions (``duration.between``, ``point.distance``); a dotted
#: function of any other namespace is a plugin's, and the console calls none
BUILT_IN_FUNCTION_NAMESPACES = frozenset(
    {"date", "datetime", "localdatetime", "localtime", "time", "duration", "point", "vector"}
    | {"db", "graph", "coll"}
)
#: rows counted at most (shown or not): past that the total is "at least"
COUNTED = 100_000
#: JavaScript's numbers hold integers exactly up to here; larger ones are sent as text
_EXACT_IN_JSON = 2**53 - 1
_INT64 = (-(2**63), 2**63 - 1)
_ACCESS_MODE = "Neo.ClientError.Statement.AccessMode"
_TIMED_OUT = ("TransactionTimedOut", "TransactionTimedOutClientConfiguration")

_LOAD_CSV = re.compile(r"\bLOAD\s+CSV\b", re.IGNORECASE)
_IN_TRANSACTIONS = re.compile(r"\bIN\s+(?:\d+\s+)?(?:CONCURRENT\s+)?TRANSACTIONS\b", re.I)
#: what may lead a statement: EXPLAIN, PROFILE and query options (``CYPHER 5 runtime=slotted``)
_LEADING_OPTIONS = re.compile(
    r"^\s*(?:(?:EXPLAIN|PROFILE|CYPHER(?:\s+(?:\d+(?:\.\d+)?|\w+\s*=\s*\w+))*)\s+)*",
    re.IGNORECASE,
)
_ADMIN_START = re.compile(
    r"^(SHOW|TERMINATE|GRANT|DENY|REVOKE|ALTER|START|STOP|ENABLE|DRYRUN|RENAME)\b",
    re.IGNORECASE,
)
_ADMIN_OBJECT = re.compile(
    r"\b(?:CREATE|DROP)\s+(?:OR\s+REPLACE\s+)?(?:USER|ROLE|DATABASE|COMPOSITE|ALIAS|SERVER)\b",
    re.IGNORECASE,
)
_USE = re.compile(r"(?:^|\{)\s*USE\b", re.IGNORECASE)
_LEADING_MODE = re.compile(r"^\s*(?:EXPLAIN|PROFILE)\b", re.IGNORECASE)


@dataclass(frozen=True)
class Limits:
    rows: int = 1000
    bytes: int = 5_000_000
    timeout: float = 30.0


@dataclass(frozen=True)
class StatementResult:
    statement: str
    columns: list[str]
    rows: list[list[Any]]
    #: rows the query returned; more than ``len(rows)`` when a limit cut them
    total: int
    #: False when counting stopped at :data:`COUNTED` rows (``total`` is then "at least")
    complete: bool = True
    #: why fewer rows are shown than counted: "" (none were cut), "rows" or "bytes"
    cut: str = ""

    def to_dict(self) -> dict[str, Any]:
        return asdict(self)


# -- the text -------------------------------------------------------------------------------


def refuse_text(statement: str) -> None:
    """Raise :class:`QueryRefused` for what the console never sends to Neo4j."""
    code = code_only(statement)
    leading = _LEADING_OPTIONS.match(code)
    body = code[leading.end() if leading else 0 :]
    if _LOAD_CSV.search(code):
        raise QueryRefused(f"{_ONLY_READS}: LOAD CSV (reading files and URLs) is refused.")
    if _IN_TRANSACTIONS.search(code):
        raise WriteRefused(
            f"{_ONLY_READS}, one transaction per statement: CALL {{ ... }} IN TRANSACTIONS "
            "is refused."
        )
    if _ADMIN_START.search(body) or _ADMIN_OBJECT.search(code):
        raise QueryRefused(
            f"{_ONLY_READS}: administration commands (SHOW, TERMINATE, users, roles, "
            "databases) are refused."
        )
    if _USE.search(body):
        raise QueryRefused(f"{_ONLY_READS} of robotale's database: USE is refused.")
    for before, name in dotted_calls(statement):
        if before.upper() != "CALL" and not _built_in_function(name):
            raise QueryRefused(
                f"{_ONLY_READS}: the function {name} is not one of Neo4j's own, and a "
                "plugin's functions are refused."
            )


def _built_in_function(name: str) -> bool:
    return name.split(".", 1)[0].lower() in BUILT_IN_FUNCTION_NAMESPACES


def checked_parameters(parameters: Mapping[str, Any] | None) -> dict[str, Any]:
    """The parameters, once every integer in them fits Neo4j's 64 bits."""
    values = dict(parameters or {})
    for name, value in values.items():
        if not isinstance(name, str):
            raise InputError(f"The parameter name {name!r} is not text.")
        _check_integers(name, value)
    return values


def _check_integers(name: str, value: Any) -> None:
    if isinstance(value, int) and not isinstance(value, bool):
        if not _INT64[0] <= value <= _INT64[1]:
            raise InputError(
                f"The parameter ${name} holds {value}, outside Neo4j's 64-bit integers; "
                "send it as text or as a float."
            )
    elif isinstance(value, list | tuple):
        for item in value:
            _check_integers(name, item)
    elif isinstance(value, dict):
        for item in value.values():
            _check_integers(name, item)


# -- the plan -------------------------------------------------------------------------------


def refuse_plan(
    session: neo4j.Session,
    statement: str,
    parameters: dict[str, Any],
    database: str,
    verdicts: PlanVerdicts | None = None,
) -> bool:
    """Ask Neo4j for the plan of ``statement`` (nothing runs) and refuse what it would do
    beyond reading ``database`` (:func:`robotale.ekg.plan_check.check_plan`); a plan
    ``verdicts`` has accepted before is not asked for again. Returns whether the plan calls
    a function whose value changes by itself (:func:`robotale.ekg.answer_cache.volatile`)."""
    key = verdicts.key(statement, parameters, database) if verdicts else None
    if verdicts is not None and key is not None and key in verdicts:
        return verdicts.volatile(key)
    code = code_only(statement)
    leading = _LEADING_MODE.match(code)
    body = statement[leading.end() :] if leading else statement
    summary = session.run("EXPLAIN " + body, parameters).consume()
    server = summary.server
    plan = summary.plan or {}
    check_plan(plan, database, built_in_functions(session, server.address))
    changing = answer_cache.volatile(plan)
    if verdicts is not None and key is not None:
        verdicts.accept(key, changing)
    return changing


class PlanVerdicts:
    """The plans one server and user accepted, by statement, parameter values and database.

    An ``EXPLAIN`` is a round trip per statement on every request; the console's users ask
    the same questions again and again. The key holds the parameter values, not only their
    types: ``USE graph.byName($name)`` reads a database named by a value, so only the same
    values make the same plan. Refusals are not kept (they cost no query), nor requests whose
    parameters are large (:data:`KEY_BYTES`); at most :data:`SIZE` verdicts, the oldest
    forgotten first."""

    SIZE = 512
    KEY_BYTES = 4096

    def __init__(self) -> None:
        #: accepted plans, each with whether it calls a volatile function
        self._accepted: dict[tuple[str, str, str], bool] = {}
        # a worker's threads share the verdicts: forgetting the oldest iterates the dict
        self._lock = threading.Lock()

    def key(
        self, statement: str, parameters: dict[str, Any], database: str
    ) -> tuple[str, str, str] | None:
        try:
            values = json.dumps(parameters, sort_keys=True, allow_nan=False)
        except (TypeError, ValueError):  # not plain JSON: ask Neo4j every time
            return None
        if len(values) + len(statement) > self.KEY_BYTES:
            return None
        return (database, statement, values)

    def __contains__(self, key: object) -> bool:
        return key is not None and key in self._accepted

    def volatile(self, key: tuple[str, str, str]) -> bool:
        return self._accepted.get(key, True)

    def accept(self, key: tuple[str, str, str], volatile: bool) -> None:
        with self._lock:
            self._accepted[key] = volatile
            while len(self._accepted) > self.SIZE:
                del self._accepted[next(iter(self._accepted))]


def built_in_functions(session: neo4j.Session, server: object) -> frozenset[str]:
    """The names of Neo4j's built-in functions, as ``server`` lists them (asked once per
    process and server: the list changes only with the server's version)."""
    address = str(server)
    if address not in _BUILT_IN:
        records = session.run(cypher("console_built_in_functions")).values()
        _BUILT_IN[address] = frozenset(str(name) for (name,) in records)
    return _BUILT_IN[address]


_BUILT_IN: dict[str, frozenset[str]] = {}


# -- running --------------------------------------------------------------------------------


def run_read_only(
    driver: Driver,
    text: str,
    parameters: Mapping[str, Any] | None = None,
    row_limit: int = Limits.rows,
    timeout: float = Limits.timeout,
    byte_limit: int = Limits.bytes,
    database: str | None = None,
    metadata: Mapping[str, Any] | None = None,
    verdicts: PlanVerdicts | None = None,
    answers: AnswerCache | None = None,
) -> list[StatementResult]:
    """Run each statement of ``text`` (separated by ``;``) in its own read transaction,
    which carries ``metadata`` (``SHOW TRANSACTIONS`` finds it by that); ``verdicts`` keeps
    the plans accepted on this driver's server as its user, ``answers`` the answers given
    on it (:mod:`robotale.ekg.answer_cache`: only while the database is unchanged).

    Every statement is checked (text, then plan) before the first one runs. Raises
    :class:`QueryRefused` (:class:`WriteRefused` for writes) for what the console does not
    run and :class:`InputError` when Neo4j rejects a statement, each with one sentence.
    """
    statements = split_statements(text)
    if not statements:
        raise InputError("Type a Cypher query (or pick an example) to run.")
    values = checked_parameters(parameters)
    for statement in statements:
        refuse_text(statement)
    limits = Limits(row_limit, byte_limit, timeout)
    database = database or default_database()
    key = (
        answers.key(database, text, values, row_limit, byte_limit) if answers is not None else None
    )
    with driver.session(database=database, default_access_mode=neo4j.READ_ACCESS) as session:
        try:
            if answers is None or key is None:
                return _checked_and_run(session, statements, values, limits, database, verdicts,
                                        metadata)[0]  # fmt: skip
            with answers.alone(key, timeout):
                before = answer_cache.mark(session)
                kept = answers.get(key, before)
                if kept is not None:
                    return [StatementResult(**result) for result in kept]
                results, changing = _checked_and_run(
                    session, statements, values, limits, database, verdicts, metadata
                )
                # kept only when nothing was committed while it ran (the bookmark is the same)
                if not changing and answer_cache.mark(session) == before:
                    answers.put(key, before, [result.to_dict() for result in results])
                return results
        except (ServiceUnavailable, SessionExpired):
            raise
        except (Neo4jError, DriverError) as error:
            raise explain(error) from None


def _checked_and_run(
    session: neo4j.Session,
    statements: list[str],
    values: dict[str, Any],
    limits: Limits,
    database: str,
    verdicts: PlanVerdicts | None,
    metadata: Mapping[str, Any] | None,
) -> tuple[list[StatementResult], bool]:
    """The statements' results, once every plan was accepted, and whether any plan calls a
    volatile function."""
    changing = False
    for statement in statements:
        changing = refuse_plan(session, statement, values, database, verdicts) or changing
    return [
        _run(session, statement, values, limits, metadata) for statement in statements
    ], changing


def _run(
    session: neo4j.Session,
    statement: str,
    parameters: dict[str, Any],
    limits: Limits,
    metadata: Mapping[str, Any] | None = None,
) -> StatementResult:
    # An explicit transaction: the driver retries none of it (a query that exhausted the
    # server's memory once fails once). The timeout is the transaction's, kept by Neo4j.
    with session.begin_transaction(timeout=limits.timeout, metadata=dict(metadata or {})) as tx:
        result = tx.run(statement, parameters)
        columns = list(result.keys())
        rows: list[list[Any]] = []
        total, size, cut = 0, 0, ""
        for record in result:
            total += 1
            if not cut:
                row = [cell(value) for value in record.values()]
                size += len(json.dumps(row))
                if total > limits.rows or size > limits.bytes:
                    cut = "rows" if total > limits.rows else "bytes"
                else:
                    rows.append(row)
            if total >= COUNTED:
                return StatementResult(statement, columns, rows, total, False, cut or "rows")
        return StatementResult(statement, columns, rows, total, True, cut)


def explain(error: Exception) -> InputError:
    """Neo4j's refusal as one sentence."""
    code = getattr(error, "code", "") or ""
    if code == _ACCESS_MODE:
        return WriteRefused(
            "The console only reads, and this query would change the graph; run writes "
            "with robotale's commands or in Neo4j Browser."
        )
    if code.endswith(_TIMED_OUT):
        return InputError(
            "The query ran longer than the console allows: narrow it (a LIMIT, a WHERE on the log)."
        )
    if "OutOfMemory" in code or "MemoryPool" in code:
        return InputError(
            "The query needs more memory than Neo4j gives one query: narrow it (a LIMIT, a "
            "WHERE on the log)."
        )
    message = (getattr(error, "message", None) or str(error) or type(error).__name__).strip()
    first = message.splitlines()[0] if message else type(error).__name__
    return InputError(f"Neo4j could not run the query: {_shortened(first, 300)}")


def _shortened(text: str, length: int) -> str:
    return text if len(text) <= length else text[: length - 1] + "…"


# -- values as JSON -------------------------------------------------------------------------


def cell(value: Any) -> Any:
    """A result value as JSON: graph elements as Neo4j Browser writes them, times as ISO text,
    non-finite floats and integers beyond JavaScript's exact range as text."""
    if isinstance(value, Node):
        labels = "".join(f":{label}" for label in sorted(value.labels))
        return f"({labels} {_properties(value)})"
    if isinstance(value, Relationship):
        return f"[:{value.type} {_properties(value)}]"
    if isinstance(value, Path):
        return [cell(element) for element in _path_elements(value)]
    if isinstance(value, list | tuple) and not hasattr(value, "srid"):
        return [cell(item) for item in value]
    if isinstance(value, dict):
        return {str(key): cell(item) for key, item in value.items()}
    if value is None or isinstance(value, bool | str):
        return value
    if isinstance(value, int):
        return value if abs(value) <= _EXACT_IN_JSON else str(value)
    if isinstance(value, float):
        return value if math.isfinite(value) else _NON_FINITE[str(value)]
    if isinstance(value, bytes | bytearray):
        return value.hex()
    if hasattr(value, "iso_format"):
        return value.iso_format()
    return str(value)


_NON_FINITE = {"nan": "NaN", "inf": "Infinity", "-inf": "-Infinity"}


def _properties(entity: Node | Relationship) -> str:
    shown = ", ".join(f"{key}: {_literal(cell(value))}" for key, value in sorted(entity.items()))
    return "{" + shown + "}"


def _literal(value: Any) -> str:
    return repr(value) if isinstance(value, str) else str(value)


def _path_elements(path: Path) -> list[Node | Relationship]:
    # a path's relationships always have both ends (the driver types their ends as optional)
    elements: list[Node | Relationship] = [path.start_node]
    for relationship in path.relationships:
        elements += [relationship, cast(Node, relationship.end_node)]
    return elements


# -- the capped process ---------------------------------------------------------------------


#: the transaction metadata key that names a console request (the watchdog looks for it)
REQUEST_KEY = "robotale_console"


def answer(request: Mapping[str, Any], drivers: Connections) -> dict[str, Any]:
    """Run one console request (connection, text, parameters, limits) and say how it went:
    ``{"results": [...]}`` or ``{"error": sentence, "kind": class name}``. ``drivers`` keeps
    one connected driver per server and user across requests, with the plans it accepted."""
    where = Settings(request["uri"], request["user"], request["password"], True)
    try:
        driver, verdicts, answers = drivers.get(where)
        results = run_read_only(
            driver,
            request["text"],
            request.get("parameters"),
            row_limit=request["rows"],
            timeout=request["timeout"],
            byte_limit=request["bytes"],
            database=request["database"],
            metadata={REQUEST_KEY: request.get("id", "")},
            verdicts=verdicts,
            answers=answers,
        )
    except RobotaleError as error:
        return {"error": str(error), "kind": type(error).__name__}
    except (ServiceUnavailable, SessionExpired):
        drivers.forget(where)
        return {"error": unreachable_message(where), "kind": ServerError.__name__}
    return {"results": [result.to_dict() for result in results]}


class Connections:
    """One connected driver per server and user, with the plans it accepted and the answers
    it gave, shared by the threads of a worker (the driver is thread-safe; each request opens
    its own session)."""

    def __init__(self) -> None:
        self._drivers: dict[tuple[str, str, str], tuple[Driver, PlanVerdicts, AnswerCache]] = {}
        self._lock = threading.Lock()

    def get(self, where: Settings) -> tuple[Driver, PlanVerdicts, AnswerCache]:
        key = (where.uri, where.user, where.password)
        with self._lock:
            if key not in self._drivers:
                self._drivers[key] = (connect(where), PlanVerdicts(), AnswerCache())
            return self._drivers[key]

    def forget(self, where: Settings) -> None:
        with self._lock:
            found = self._drivers.pop((where.uri, where.user, where.password), None)
        if found:
            found[0].close()


#: the C stack of each of a worker's threads (a deeply nested value is walked recursively)
THREAD_STACK = 8 * 1024 * 1024


def serve(megabytes: int, threads: int) -> None:
    """Answer requests, one JSON line each on stdin, with one JSON line each on stdout (with
    the request's ``id``), up to ``threads`` at once, in a process whose memory may grow by
    ``megabytes``; end at the end of stdin (the pool ends a process after a request ran out
    of memory: what it left behind is not worth keeping)."""
    threading.stack_size(THREAD_STACK)
    # The cap is on top of what Python and the driver already map (their size varies), and
    # of the threads' stacks, which are address space whether used or not.
    limit = _mapped_bytes() + megabytes * 1024 * 1024 + threads * THREAD_STACK
    resource.setrlimit(resource.RLIMIT_AS, (limit, limit))
    drivers = Connections()
    output = threading.Lock()
    sys.stdout.write("ready\n")  # the pool counts a request's time from here on
    sys.stdout.flush()
    with ThreadPoolExecutor(threads, thread_name_prefix="console") as executor:
        for line in sys.stdin:
            executor.submit(_reply, line, drivers, output)


def _reply(line: str, drivers: Connections, output: threading.Lock) -> None:
    started = time.monotonic()
    request_id = ""
    try:
        request = json.loads(line)
        request_id = request.get("id", "")
        reply = answer(request, drivers)
        # allow_nan=False: a value cell() let through as NaN would be invalid JSON; fail loudly.
        text = json.dumps(
            {"id": request_id, "seconds": time.monotonic() - started, **reply}, allow_nan=False
        )
    except MemoryError:
        text = json.dumps({"id": request_id, "error": "memory", "kind": "MemoryError"})
    with output:
        sys.stdout.write(text + "\n")
        sys.stdout.flush()


def _mapped_bytes() -> int:
    try:
        with open("/proc/self/statm") as statm:
            return int(statm.read().split()[0]) * resource.getpagesize()
    except OSError:  # no /proc (not Linux): count a generous start instead
        return 1024**3


if __name__ == "__main__":
    serve(int(sys.argv[1]), int(sys.argv[2]))
