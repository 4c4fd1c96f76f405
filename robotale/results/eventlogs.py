"""The event log an analysis reads (``discover``, ``perspectives``, ``report``): a file, or a
log stored in Neo4j by its name."""

from __future__ import annotations

import sys
from collections.abc import Sequence
from pathlib import Path

import pandas as pd

from robotale.errors import InputError
from robotale.eventlog.readers import parse_mapping, read_log_with_reading
from robotale.eventlog.reading import Reading, format_reading


def read_event_log(
    log: Path | None = None,
    *,
    log_name: str | None = None,
    mapping: Sequence[str] = (),
    case_column: str | None = None,
    case_gap: str | None = None,
) -> pd.DataFrame:
    """A CSV/XES file (``log``, read with the ``--map`` items, ``case_column`` and
    ``case_gap``; how it was read goes to stderr) or, with ``log_name``, a log stored in
    Neo4j."""
    if log_name:
        # the graph database's driver takes a second to import: only a stored log needs it
        from robotale.discovery.ekg import read_stored_log

        return read_stored_log(log_name)
    if not log:
        raise InputError("name an event log: a CSV or XES file, or --log NAME for a stored one.")
    events, reading = read_log_with_reading(
        log, parse_mapping(mapping), case=case_column, case_gap=case_gap
    )
    report_reading(reading)
    return events


def report_reading(reading: Reading) -> None:
    """The short form of how a file was read, on stderr so it never mixes with the output."""
    print(format_reading(reading, short=True), file=sys.stderr)
