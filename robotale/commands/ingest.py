"""``robotale ingest`` (an event log or recordings into the graph) and ``robotale logs``."""

from __future__ import annotations

import shlex
import uuid
from collections.abc import Sequence
from pathlib import Path
from typing import Any

from robotale.ekg.append import append_ekg
from robotale.ekg.build import refuse_existing
from robotale.ekg.bulk import AUTO, BULK, build_log
from robotale.ekg.columnar import delete_copies
from robotale.ekg.connection import session_driver, settings
from robotale.ekg.disk_space import check_space
from robotale.ekg.keys import default_entities
from robotale.ekg.logs import FAILED, delete_log_locked, list_logs, log_summary, require_log
from robotale.ekg.ocel_append import append_objects
from robotale.errors import InputError
from robotale.eventlog.logkinds import RECORDINGS
from robotale.eventlog.logsource import log_name, open_log
from robotale.eventlog.options import PrepareOptions
from robotale.eventlog.reading import format_reading
from robotale.neo4j_server.server import LocalServer
from robotale.results.storing import default_keys, describe, pages_when, prepare_pages
from robotale.timings import stage, watch_server


def ingest_command(
    path: Path,
    *,
    log: str | None = None,
    entities: str | None = None,
    aggregate: Sequence[str] | None = None,
    mapping: Sequence[str] = (),
    case: str | None = None,
    case_gap: str | None = None,
    replace: bool = False,
    append: bool = False,
    objects: Path | None = None,
    skip_bad: bool = False,
    pages: str | None = None,
    build: str = AUTO,
    **preparation: Any,
) -> int:
    """Store the log at ``path`` (CSV, XES, OCEL 2.0, Parquet, or recordings prepared as
    ``prepare`` does) in Neo4j as ``log`` (default: the file's or folder's name);
    ``preparation`` holds the fields of :class:`~robotale.eventlog.options.PrepareOptions`
    (--tags, --actions, --auto ...). With ``append`` its runs are added to the stored log of
    that name. ``objects``: the folder of a CSV log's object tables (``<Type>.csv``). An
    object-centric log's object types are its entity types unless ``entities`` names others.
    ``build``: how a new log's graph is written (:func:`~robotale.ekg.bulk.build_log`)."""
    if append and replace:
        raise InputError("--append adds runs to a log and --replace rebuilds it: give one.")
    if append and build == BULK:
        raise InputError(
            "--build bulk writes a new log into an empty database and --append adds runs to a "
            "stored one: give one."
        )
    pages = pages_when(pages)
    if not settings().from_env:  # robotale's own local server: its CPU time counts in timings
        watch_server(_local_server_pid)
    if log is not None and not log.strip():
        raise InputError(
            f"--log {log!r} names no log: give it a name, or leave --log out to use "
            f"{log_name(path)!r}."
        )
    name = log or log_name(path)
    # the bulk build tells this process's own connections from other clients' by it
    agent = f"robotale-ingest/{uuid.uuid4().hex}"
    if not (append or replace):
        # before the log is read: a name in use is refused at once, whatever the log's size
        # (the build asks again under the write lock)
        with (
            stage("connect, and check the name is free"),
            session_driver(user_agent=agent) as driver,
        ):
            refuse_existing(driver, name)
    skipped: list[Path] | None = [] if skip_bad else None
    with stage("read the log"):
        opened = open_log(
            path,
            mapping=mapping,
            case=case,
            case_gap=case_gap,
            objects=objects,
            preparation=PrepareOptions.given(preparation),
            skipped=skipped,
        )
    events, found_objects = opened.events, opened.objects
    if opened.reading is not None:
        # on stdout, as part of ingest's report: its stderr holds only a failure's sentence
        print(format_reading(opened.reading, short=True))
    chosen = split_names(entities) if entities else None
    if chosen is None and found_objects is not None:
        chosen = found_objects.entity_types
    names = {"entities": chosen}
    keys = aggregate or default_keys(events, chosen)
    with session_driver(user_agent=agent) as driver:
        entity_columns = chosen if chosen is not None else default_entities(events.columns)
        with stage("check the disk space"):
            check_space(driver, events, name, entity_columns, len(keys))
        if append:
            # the log's columnar copy no longer matches its build: the next analysis reads
            # the whole log back from the graph and keeps that copy instead
            summary = (
                append_ekg(driver, events, name, aggregate=aggregate, **names)
                if found_objects is None
                else append_objects(driver, events, name, found_objects, aggregate=aggregate)
            )
        else:
            summary = build_log(
                driver,
                events,
                name,
                build=build,
                user_agent=agent,
                aggregate=keys,
                replace=replace,
                source=str(path),
                objects=found_objects,
                **names,
            )
        print(describe(summary, appended=append))
    # a bulk build restarted the server: new connections, with no bookmarks of the old store
    with session_driver() as driver:
        if opened.kind is RECORDINGS:
            # here, not at the top: the simulation's modules are a recording's only
            from robotale.results.site import keep_sites, run_sites

            # the Mission page's map: the simulated runs' fields, bases and objects
            keep_sites(driver, name, run_sites(path))
        with stage("the dashboard's pages"):
            prepare_pages(driver, name, pages)
    if skipped is not None and opened.kind is RECORDINGS:
        # here, not at the top: the recordings' preparation is a recording's import only
        from robotale.eventlog.preparing import kept_runs

        print(kept_runs(events["case:concept:name"].nunique(), skipped))
    return 0


def _local_server_pid() -> int | None:
    running = LocalServer().running()
    return running.pid if running is not None else None


def logs_list() -> int:
    with session_driver() as driver:
        logs = list_logs(driver)
    if not logs:
        print("No event logs in Neo4j yet: load one with `robotale ingest FILE`.")
    for log in logs:
        events = f"{log['events']:,} events" if log["events"] is not None else "no events yet"
        print(
            f"{log['name']}  [{log['status']}]  {events}  "
            f"entities: {', '.join(log['entityTypes'] or []) or '-'}  "
            f"classes: {', '.join(log['classTypes'] or []) or '-'}  created {log['created']}"
        )
        if log["status"] == FAILED:
            print(
                "  its ingest ended before it was complete; remove it with "
                f"`robotale logs delete {shlex.quote(log['name'])}`"
            )
    return 0


def logs_show(name: str) -> int:
    with session_driver() as driver:
        summary = log_summary(driver, name)
    print(f"{summary['name']}  [{summary['status']}]  from {summary['source'] or '-'}")
    for what, count in summary["counts"].items():
        print(f"  {what:<40} {count:>10,}")
    return 0


def logs_delete(name: str) -> int:
    with session_driver() as driver:
        require_log(driver, name)
        delete_log_locked(driver, name)
    delete_copies(name)
    print(f"Deleted the log {name!r}.")
    return 0


def split_names(text: str) -> list[str]:
    return [name.strip() for name in text.split(",") if name.strip()]
