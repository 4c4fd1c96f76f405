"""``robotale inspect LOG``: how robotale reads an event log, before anything is built on it."""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path

from robotale.eventlog.readers import parse_mapping, read_log_with_reading
from robotale.eventlog.reading import format_reading


def inspect_command(
    log: Path,
    *,
    mapping: Sequence[str] = (),
    case_column: str | None = None,
    case_gap: str | None = None,
) -> int:
    """Print how ``log`` is read: columns and their roles, cases, robots and their types,
    events kept and dropped (and why), missing values, notes and warnings."""
    _, reading = read_log_with_reading(
        log, parse_mapping(mapping), case=case_column, case_gap=case_gap
    )
    print(format_reading(reading))
    return 0
