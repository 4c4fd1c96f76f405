"""Handlers of the ``prepare`` command, and the preparation ``ingest`` runs on recordings
(parsers in :mod:`robotale.cli`)."""

from __future__ import annotations

import argparse
import sys
import warnings
from pathlib import Path
from typing import Any

import pandas as pd

from robotale.ingest import writers
from robotale.ingest.enrich import PreparationWarning
from robotale.ingest.prepare import TagFields, find_runs, prepare, run_manifests


def prepare_command(args: argparse.Namespace) -> int:
    source = Path(args.source)
    out = args.out or (None if args.xes or args.ocel else f"{source.resolve().name}.csv")
    log = prepare_recordings(source, args)
    written = []
    if out:
        writers.write_csv(log, out)
        written.append(out)
    if args.xes:
        writers.write_xes(log, args.xes, name=source.resolve().name)
        written.append(args.xes)
    if args.ocel:
        writers.write_ocel(log, args.ocel, runs=run_manifests(find_runs(source)))
        written.append(args.ocel)
    cases = log["case:concept:name"].nunique()
    print(f"{len(log)} events from {cases} run(s) written to {', '.join(written)}")
    return 0


def prepare_recordings(source: Path, args: argparse.Namespace) -> pd.DataFrame:
    """The event log of the recordings at ``source`` with the preparation options of ``args``
    (see :func:`prepare_reporting`)."""
    return prepare_reporting(
        source,
        tags=args.tags,
        tag_fields=TagFields.parse(args.tag_field),
        perspectives=[p for p in args.perspectives.split(",") if p.strip()],
        rate=args.rate,
        msg_files=args.msg,
        bag_time=args.bag_time,
    )


def prepare_reporting(source: Path, **options: Any) -> pd.DataFrame:
    """:func:`~robotale.ingest.prepare.prepare` with a progress bar, its warnings (completes
    without a start ...) on stderr as one ``robotale: warning:`` line each."""
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always", PreparationWarning)
        log = prepare(source, progress=True, **options)
    for warning in caught:
        if issubclass(warning.category, PreparationWarning):
            print(f"robotale: warning: {warning.message}", file=sys.stderr)
    return log
