"""``robotale ingest`` (an event log or recordings into the graph) and ``robotale logs``."""

from __future__ import annotations

import os
import shlex
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import pandas as pd
from neo4j import Driver

from robotale.commands.prepare import kept_runs, prepare_recordings
from robotale.ekg.append import append_ekg
from robotale.ekg.build import BuildSummary, build_ekg, why
from robotale.ekg.columnar import delete_copies
from robotale.ekg.connection import session_driver
from robotale.ekg.keys import built_keys, default_entities
from robotale.ekg.logs import FAILED, delete_log_locked, list_logs, log_summary, require_log
from robotale.errors import InputError
from robotale.eventlog.readers import is_parquet, parse_mapping, read_with_objects
from robotale.eventlog.reading import format_reading
from robotale.results import background

#: when ``robotale ingest`` prepares the dashboard's pages (see :func:`prepare_pages`)
PAGES = ("background", "now", "visit")
#: the environment variable that chooses it when ``--pages`` is not given
PAGES_ENV = "ROBOTALE_PAGES"


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
    tags: str | None = None,
    tag_fields: Sequence[str] = (),
    perspectives: str | None = None,
    rate: float | None = None,
    msg_files: Sequence[str] = (),
    bag_time: bool = False,
    objects: Path | None = None,
    skip_bad: bool = False,
    pages: str | None = None,
    **recording: Any,
) -> int:
    """Store the log at ``path`` (CSV, XES, OCEL 2.0, or recordings prepared as ``prepare``
    does) in Neo4j as ``log`` (default: the file's or folder's name); ``recording`` holds the
    other options of :func:`~robotale.commands.prepare.prepare_recordings` (--actions, --auto
    ...). With ``append`` its runs are added to the stored log of that name. ``objects``: the
    folder of a CSV log's object tables (``<Type>.csv``). An object-centric log's object types
    are its entity types unless ``entities`` names others."""
    if append and replace:
        raise InputError("--append adds runs to a log and --replace rebuilds it: give one.")
    pages = pages_when(pages)
    found_objects = None
    if log is not None and not log.strip():
        raise InputError(
            f"--log {log!r} names no log: give it a name, or leave --log out to use "
            f"{log_name(path)!r}."
        )
    skipped: list[Path] | None = None
    if path.is_dir() and not is_parquet(path):
        if objects is not None:
            raise InputError(
                f"{path} holds recordings: --objects applies to a CSV event log with one "
                "column per object type."
            )
        if mapping or case:
            raise InputError(
                f"{path} holds recordings: --map and --case apply to CSV and XES files "
                "(each run of a recording is its own case)."
            )
        if case_gap:
            raise InputError(
                f"{path} holds recordings: --case-gap applies to CSV and XES files "
                "(each run of a recording is its own case)."
            )
        skipped = [] if skip_bad else None
        events = prepare_recordings(
            path,
            tags=tags,
            tag_fields=tag_fields,
            perspectives=perspectives,
            rate=rate,
            msg_files=msg_files,
            bag_time=bag_time,
            skipped=skipped,
            **recording,
        )
    else:
        events, reading, found_objects = read_with_objects(
            path, parse_mapping(mapping), case, case_gap, objects
        )
        # on stdout, as part of ingest's report: its stderr holds only a failure's sentence
        print(format_reading(reading, short=True))
    if append and found_objects is not None:
        raise InputError(
            f"{path} is object-centric: --append adds runs of a log with cases; rebuild the "
            "log with --replace instead."
        )
    name = log or log_name(path)
    chosen = split_names(entities) if entities else None
    if chosen is None and found_objects is not None:
        chosen = found_objects.entity_types
    names = {"entities": chosen}
    with session_driver() as driver:
        if append:
            # the log's columnar copy no longer matches its build: the next analysis reads
            # the whole log back from the graph and keeps that copy instead
            summary = append_ekg(driver, events, name, aggregate=aggregate, **names)
        else:
            summary = build_ekg(
                driver,
                events,
                name,
                aggregate=aggregate or default_keys(events, chosen),
                replace=replace,
                source=str(path),
                objects=found_objects,
                **names,
            )
        print(describe(summary, appended=append))
        prepare_pages(driver, name, pages)
    if skipped is not None:
        print(kept_runs(events["case:concept:name"].nunique(), skipped))
    return 0


def default_keys(events: pd.DataFrame, entities: Sequence[str] | None) -> list[str]:
    """The class graphs built with a log when ``--aggregate`` names none: those the dashboard
    builds with an upload, so the Discover and Perspectives pages' first class graph is
    computed with the build's own tables instead of aggregated in Neo4j on the first visit."""
    return built_keys(default_entities(events.columns) if entities is None else entities)


def pages_when(pages: str | None) -> str:
    """When to prepare the pages: ``pages``, else ``$ROBOTALE_PAGES``, else in the background;
    checked before anything is stored."""
    chosen = pages or os.environ.get(PAGES_ENV) or "background"
    if chosen not in PAGES:
        raise InputError(
            f"--pages (or ${PAGES_ENV}) {chosen!r} is not a time to prepare the pages: give "
            f"one of {', '.join(PAGES)}."
        )
    return chosen


def prepare_pages(driver: Driver, name: str, pages: str | None = None) -> None:
    """Compute what the dashboard shows first of the stored log ``name`` (its findings,
    perspectives, runs and first timeline), kept with its build, so the first visit computes
    nothing: in a process of its own that outlives the command (``background``, the default,
    or ``$ROBOTALE_PAGES``), before returning (``now``) or not at all (``visit``: the first
    visit computes them). The log is stored already: a failure only leaves that work to it."""
    pages = pages_when(pages)
    if pages == "visit":
        return
    if pages == "background":
        try:
            process = background.start(name)
        except OSError as error:  # no process to be had: prepare here instead
            print(f"  not started in the background ({why(error)}): preparing now")
        else:
            print(
                "preparing the dashboard's findings, perspectives and timeline in the "
                f"background (process {process.pid}); a page visited before computes its own"
            )
            return
    print("preparing the dashboard's findings, perspectives and timeline ...", flush=True)
    try:
        background.prepare_now(driver, name)
    except Exception as error:  # the log is stored: a page's failure is said, not raised
        print(f"  not prepared ({why(error)}): the dashboard computes them on the first visit")


def store(log: pd.DataFrame, name: str, source: Path, **keys: Sequence[str]) -> None:
    """Store a log read elsewhere (``demo``) under ``name``, replacing one of that name."""
    with session_driver() as driver:
        summary = build_ekg(driver, log, name, replace=True, source=str(source), **keys)
        print(describe(summary))
        prepare_pages(driver, name)


def log_name(path: Path) -> str:
    """A log's default name: the file's stem, or the folder's name (also for ``.``)."""
    if is_parquet(path):  # a dataset folder is named like a file: agri.parquet
        return path.resolve().stem
    return path.resolve().name if path.is_dir() else path.stem


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


def describe(summary: BuildSummary, appended: bool = False) -> str:
    def counts(values: dict[str, int]) -> str:
        return ", ".join(f"{k} {v:,}" for k, v in sorted(values.items())) or "-"

    what = "appended" if appended else "events"
    return "\n".join(
        [
            f"Log {summary.log!r}: {summary.events:,} {what} in {summary.seconds:.1f} s",
            f"  entities  {counts(summary.entities)} (CORR {summary.corr:,})",
            f"  DF        {counts(summary.df)}",
            f"  COMM      {summary.comm:,}",
            f"  DF_C      {counts(summary.df_c)}",
        ]
    )
