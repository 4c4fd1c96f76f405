"""Handlers of the ``ingest`` and ``logs`` commands (parsers in :mod:`robotale.cli`)."""

from __future__ import annotations

import argparse
from pathlib import Path

from robotale.ekg.build import BuildSummary, build_ekg
from robotale.ekg.connection import session_driver
from robotale.ekg.logs import delete_log, list_logs, log_exists, log_summary
from robotale.errors import InputError
from robotale.ingest.readers import read_log


def ingest(args: argparse.Namespace) -> int:
    path = Path(args.path)
    log = (
        read_recordings(path, args)
        if path.is_dir()
        else read_log(path, parse_mapping(args.map), args.case)
    )
    with session_driver() as driver:
        summary = build_ekg(
            driver,
            log,
            args.log or log_name(path),
            entities=split_names(args.entities) if args.entities else None,
            aggregate=args.aggregate or ["activity"],
            replace=args.replace,
            source=str(path),
        )
    print(describe(summary))
    return 0


def log_name(path: Path) -> str:
    """A log's default name: the file's stem, or the folder's name (also for ``.``)."""
    return path.resolve().name if path.is_dir() else path.stem


def read_recordings(path: Path, args: argparse.Namespace):
    """The event log of a rosbag2 directory or a folder of runs, prepared as ``prepare`` does."""
    from robotale.ingest.commands import prepare_recordings

    if args.map or args.case:
        raise InputError(
            f"{path} holds recordings: --map and --case apply to CSV and XES files "
            "(each run of a recording is its own case)."
        )
    return prepare_recordings(path, args)


def logs_list(args: argparse.Namespace) -> int:
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
    return 0


def logs_show(args: argparse.Namespace) -> int:
    with session_driver() as driver:
        summary = log_summary(driver, args.name)
    print(f"{summary['name']}  [{summary['status']}]  from {summary['source'] or '-'}")
    for what, count in summary["counts"].items():
        print(f"  {what:<40} {count:>10,}")
    return 0


def logs_delete(args: argparse.Namespace) -> int:
    with session_driver() as driver:
        if not log_exists(driver, args.name):
            raise InputError(f"There is no log named {args.name!r} in Neo4j.")
        delete_log(driver, args.name)
    print(f"Deleted the log {args.name!r}.")
    return 0


def parse_mapping(items: list[str]) -> dict[str, str]:
    """``["Zeit=time", ...]`` as ``{"Zeit": "time"}``."""
    mapping = {}
    for item in items or []:
        column, sep, field = item.partition("=")
        if not sep or not column.strip() or not field.strip():
            raise InputError(f"--map {item!r} is not COLUMN=FIELD (e.g. --map Zeit=time).")
        mapping[column.strip()] = field.strip()
    return mapping


def split_names(text: str) -> list[str]:
    return [name.strip() for name in text.split(",") if name.strip()]


def describe(summary: BuildSummary) -> str:
    def counts(values: dict[str, int]) -> str:
        return ", ".join(f"{k} {v:,}" for k, v in sorted(values.items())) or "-"

    return "\n".join(
        [
            f"Log {summary.log!r}: {summary.events:,} events in {summary.seconds:.1f} s",
            f"  entities  {counts(summary.entities)} (CORR {summary.corr:,})",
            f"  DF        {counts(summary.df)}",
            f"  COMM      {summary.comm:,}",
            f"  DF_C      {counts(summary.df_c)}",
        ]
    )
