"""Storing a log as the command line does: the graph built, its summary said, and what the
dashboard shows first of it prepared beside it (``ingest`` and ``demo`` both store so)."""

from __future__ import annotations

import os
from collections.abc import Sequence
from pathlib import Path

import pandas as pd
from neo4j import Driver

from robotale.ekg.build import BuildSummary, build_ekg, why
from robotale.ekg.connection import session_driver
from robotale.ekg.keys import DEFAULT_AGGREGATE, built_keys, default_entities
from robotale.errors import InputError

#: when ``robotale ingest`` prepares the dashboard's pages (see :func:`prepare_pages`)
PAGES = ("background", "now", "visit")
#: the environment variable that chooses it when ``--pages`` is not given
PAGES_ENV = "ROBOTALE_PAGES"


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
    # here, not at the top: the findings' and missions' modules it brings cost an ingest
    # that prepares no page some 0.15 s of CPU before its build
    from robotale.results import background

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
