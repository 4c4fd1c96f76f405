"""Storing a log as the command line does: the graph built, its summary said, and what the
dashboard shows first of it prepared beside it (``ingest`` and ``demo`` both store so)."""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path

import pandas as pd
from neo4j import Driver

from robotale.ekg.build import BuildSummary, build_ekg, why
from robotale.ekg.connection import session_driver
from robotale.ekg.keys import DEFAULT_AGGREGATE
from robotale.results.findings import prepare
from robotale.results.logdata import LogData


def store(
    log: pd.DataFrame,
    name: str,
    source: Path,
    *,
    entities: Sequence[str] | None = None,
    aggregate: Sequence[str | Sequence[str]] = DEFAULT_AGGREGATE,
) -> None:
    """Store a log read elsewhere (``demo``) under ``name`` with its ``entities`` and
    ``aggregate`` keys, replacing one of that name."""
    with session_driver() as driver:
        summary = build_ekg(
            driver,
            log,
            name,
            entities=entities,
            aggregate=aggregate,
            replace=True,
            source=str(source),
        )
        print(describe(summary))
        prepare_pages(driver, name)


def prepare_pages(driver: Driver, name: str) -> None:
    """Compute what the dashboard shows first of the stored log ``name`` (its findings,
    perspectives, runs and first timeline), kept with its build, so the first visit computes
    nothing. The log is stored already: a failure here only leaves that work to the visit."""
    print("preparing the dashboard's findings, perspectives and timeline ...", flush=True)
    try:
        prepare(driver, LogData(), name)
    except Exception as error:  # the log is stored: a page's failure is said, not raised
        print(f"  not prepared ({why(error)}): the dashboard computes them on the first visit")


def describe(summary: BuildSummary, appended: bool = False) -> str:
    """What a build stored, counted, as ``ingest`` prints it."""

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
