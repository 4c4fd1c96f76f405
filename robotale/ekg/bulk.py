"""Build a log's graph with Neo4j's offline importer when that is faster: :func:`build_log`.

Writing through Cypher costs Neo4j Community a fixed amount of server CPU per record, so a
large log is built several times faster by ``neo4j-admin database import full``, which writes
the store files directly. That needs the server stopped, so robotale takes that path only
for its own local server, a database that holds no graph yet, and nobody else connected:
it writes the import files from the tables the online build would write
(:mod:`robotale.ekg.import_files`), stops the server, imports, starts it again
(:func:`robotale.neo4j_server.importer.import_offline`), creates the indexes and constraints
the online build creates and waits until they are online. Everything else is built online
(:func:`robotale.ekg.build.build_ekg`).

``build``: ``online`` or ``bulk`` force a path (``bulk`` refuses, in one sentence, where it
cannot be taken); ``auto`` takes the bulk path from :data:`BULK_FROM` events on when it can.
"""

from __future__ import annotations

import dataclasses
import shlex
import tempfile
import time
from collections.abc import Callable, Sequence
from concurrent.futures import ThreadPoolExecutor, wait
from pathlib import Path

import pandas as pd
from neo4j import Driver

from robotale.ekg.build import (
    BuildSummary,
    Prepared,
    build_ekg,
    ensure_schema_together,
    finish_log,
    prepare,
    summarise,
    undo_after_failure,
)
from robotale.ekg.columnar import delete_copies, store_copy
from robotale.ekg.connection import (
    client_connections,
    database,
    read_rows,
    session_driver,
    settings,
)
from robotale.ekg.import_files import Instant, instant, unsupported, write_import_files
from robotale.ekg.keys import DEFAULT_AGGREGATE
from robotale.ekg.logs import delete_log
from robotale.ekg.writelock import holder, release, take
from robotale.errors import InputError, ServerError
from robotale.eventlog.objects import Objects
from robotale.neo4j_server.importer import RestartFailed, import_offline
from robotale.neo4j_server.server import LocalServer
from robotale.queries import cypher
from robotale.timings import stage

ONLINE, BULK, AUTO = "online", "bulk", "auto"
BUILDS = (AUTO, ONLINE, BULK)
#: from this many events on ``auto`` takes the bulk path. It cost 1.8x the CPU of writing
#: online to a server that has run a build before at 100,000 events and 1.2x at 200,000 (the
#: restart, the importer's JVM and the indexes filled on a cold server are fixed costs; the
#: restart also leaves the server cold for the next command): the two cross at about 300,000
#: (docs/benchmarks.md, "Where the whole ingest's time goes")
BULK_FROM = 300_000
#: how long the indexes and constraints may take to come online after an import
INDEX_WAIT = 3600


def build_log(
    driver: Driver,
    log: pd.DataFrame,
    name: str,
    *,
    build: str = AUTO,
    user_agent: str = "",
    entities: Sequence[str] | None = None,
    aggregate: Sequence[str | Sequence[str]] = DEFAULT_AGGREGATE,
    replace: bool = False,
    source: str = "",
    objects: Objects | None = None,
    progress: bool = True,
) -> BuildSummary:
    """Store ``log`` as the graph ``name``, online or through the importer as ``build`` says.

    ``user_agent``: the one ``driver`` connects with; any other client connected keeps the
    bulk path from being taken. The other arguments are :func:`build_ekg`'s.
    """
    if build not in BUILDS:
        raise InputError(f"--build {build!r} is not one of {', '.join(BUILDS)}.")
    with stage("compute the graph's tables"):
        prepared = prepare(log, entities, aggregate, name)
    with stage("choose the build"):
        reason = (
            "--build online" if build == ONLINE else refusal(driver, prepared, objects, user_agent)
        )
    if build == AUTO and reason is None and len(log) < BULK_FROM:
        reason = f"fewer than {BULK_FROM:,} events"
    if build == BULK and reason is not None:
        raise InputError(f"--build bulk cannot be used here: {reason}.")
    if reason is not None:
        return build_ekg(
            driver,
            log,
            name,
            entities=entities,
            aggregate=aggregate,
            replace=replace,
            source=source,
            progress=progress,
            objects=objects,
            prepared=prepared,
        )
    say: Callable[[str], None] = _say if progress else lambda line: None
    return build_bulk(driver, log, name, prepared, user_agent, source, say)


def refusal(
    driver: Driver, prepared: Prepared, objects: Objects | None, user_agent: str
) -> str | None:
    """Why the bulk path cannot build this log here (None: it can)."""
    if objects is not None:
        return "an object-centric log's objects are written online"
    if settings().from_env:
        return "NEO4J_URI names a server robotale does not manage (it can only be stopped by it)"
    if LocalServer().running() is None:
        return "the local Neo4j is not running"
    if why := unsupported(prepared.tables, prepared.classes):
        return why
    return _occupied(driver, None, user_agent)


def _occupied(driver: Driver, run: str | None, user_agent: str) -> str | None:
    """Why the database cannot be replaced now: it holds nodes (besides the lock of ``run``)
    or another client is connected."""
    nodes = read_rows(driver, cypher("ekg_stored_nodes"), run=run)[0]["nodes"]
    if nodes:
        return f"the database {database()!r} holds {nodes:,} nodes already (it must be empty)"
    others = client_connections(driver, user_agent)
    if others:
        first = others[0]
        return (
            f"{len(others)} other client connection(s) to the local Neo4j are open (the "
            f"first from {first['clientAddress']}, {first['userAgent'] or 'unnamed'}); the "
            "import stops the server"
        )
    return None


def build_bulk(
    driver: Driver,
    log: pd.DataFrame,
    name: str,
    prepared: Prepared,
    user_agent: str,
    source: str = "",
    progress: Callable[[str], None] = lambda line: None,
) -> BuildSummary:
    """Build the graph of ``prepared`` into the empty database of the local server through
    the importer (see the module's text); the database is left empty when that fails."""
    started = time.perf_counter()
    server = LocalServer()
    tables, classes = prepared.tables, prepared.classes
    with stage("the indexes and constraints before the import"):
        ensure_schema_together(driver)
    run = take(driver, name, "ingesting")
    try:
        if why := _occupied(driver, run, user_agent):
            raise InputError(f"--build bulk cannot be used here: {why}.")
        node, lock = _log_nodes(driver, name, run, prepared, source)
    except BaseException:
        release(driver, name, run)
        raise
    server.home.mkdir(parents=True, exist_ok=True)
    failed: ServerError | None = None
    with tempfile.TemporaryDirectory(dir=server.home, prefix="import-") as folder:
        progress(f"Writing the import files of {len(tables.events):,} events ...")
        try:
            with stage("write the import files"):
                files = write_import_files(Path(folder), tables, classes, node, lock)
        except BaseException:  # e.g. a full disk: the server still runs
            release(driver, name, run)
            raise
        try:
            import_offline(server, database(), files, progress)
        except RestartFailed:
            raise  # the lock stays; with its writer gone it counts as stale
        except ServerError as error:
            failed = error
    # The server's connections are gone and the driver's bookmarks name transactions of the
    # store the import replaced (the new one would wait for them): a new driver.
    with session_driver(user_agent=user_agent) as fresh:
        try:
            if failed is None:
                _finish(fresh, name, log, prepared, progress)
        finally:
            release(fresh, name, run)
    if failed is not None:
        raise ServerError(
            f"The bulk import of the log {name!r} failed: {failed}; the database is as it was "
            "before."
        ) from failed
    summary = summarise(name, tables, classes)
    return dataclasses.replace(summary, seconds=time.perf_counter() - started)


def _log_nodes(
    driver: Driver, name: str, run: str, prepared: Prepared, source: str
) -> tuple[dict[str, object], dict[str, object]]:
    """The properties of the log's Log node as the online build begins it, and of the write
    lock ``run`` holds (imported with the graph: the lock lasts through the import)."""
    tables = prepared.tables
    lock = holder(driver, name)
    assert lock is not None and lock.run == run, "the lock was taken a moment ago"
    node = {
        "name": name,
        "status": "building",
        "run": run,
        "source": source,
        "created": instant(pd.Timestamp.now(tz="UTC")),
        "properties": list(tables.events.columns),
        "entityTypes": tables.entities["type"].unique().tolist(),
    }
    taken = {
        "name": name,
        "run": run,
        "host": lock.host,
        "pid": lock.pid,
        "pidStart": lock.pid_start,
        "started": Instant(lock.started),
    }
    return node, taken


def _finish(
    driver: Driver,
    name: str,
    log: pd.DataFrame,
    prepared: Prepared,
    progress: Callable[[str], None],
) -> None:
    """After the import: the indexes and constraints, created together, and meanwhile the
    columnar copy kept (it needs no index); then the Log node completed. What was imported is
    removed again when that fails."""
    progress("Creating the indexes and constraints ...")
    with ThreadPoolExecutor(max_workers=1) as beside:
        copying = beside.submit(store_copy, driver, name, log)
        try:
            with stage("create the indexes and constraints"):
                ensure_schema_together(driver)
            with stage("wait for the indexes"):
                driver.execute_query(
                    cypher("ekg_await_indexes"), seconds=INDEX_WAIT, database_=database()
                )
            with stage("complete the Log node"):
                finish_log(driver, name, prepared.tables.events, prepared.classes)
        except BaseException as error:
            wait([copying])
            delete_copies(name)  # the copy of a log that is not kept
            undo_after_failure(
                error,
                lambda: delete_log(driver, name),
                f"Finishing the imported log {name!r} failed",
                f"`robotale logs delete {shlex.quote(name)}`",
            )
    with stage("wait for the columnar copy"):
        copying.result()


def _say(line: str) -> None:
    print(line, flush=True)
