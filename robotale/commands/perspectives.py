"""``robotale perspectives``: the perspectives of :mod:`robotale.enhancement.registry`."""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path

from robotale.enhancement.registry import perspective_kind
from robotale.enhancement.report import all_perspectives, write_report
from robotale.enhancement.spatial import Field
from robotale.errors import InputError, require_range
from robotale.results.eventlogs import read_event_log


def perspectives_command(
    log: Path | None = None,
    *,
    log_name: str | None = None,
    mapping: Sequence[str] = (),
    case_column: str | None = None,
    case_gap: str | None = None,
    out: Path | None = None,
    json_out: Path | None = None,
    activity: str | None = None,
    robot: str | None = None,
    field: str | None = None,
    threshold: float | None = None,
    delay: float | None = None,
    only: Sequence[str] | None = None,
) -> int:
    """The perspectives of a log (a file or ``log_name``) as HTML (``out``) and/or JSON; all
    of them, or those named in ``only``."""
    if not out and not json_out:
        raise InputError("say where the report goes: --out report.html and/or --json report.json.")
    if threshold is not None:
        require_range(threshold, "--threshold", 0, 100, unit=" percent")
    if delay is not None:
        require_range(delay, "--delay", 0, unit=" seconds")
    area = Field.parse(field) if field else None
    events = read_event_log(
        log, log_name=log_name, mapping=mapping, case_column=case_column, case_gap=case_gap
    )
    options = {"delay_threshold": delay} | ({} if threshold is None else {"threshold": threshold})
    results = all_perspectives(
        events, activity=activity, robot=robot, field=area, only=only, **options
    )
    title = f"robotale perspectives: {log_name or Path(log or '').name}"
    write_report(results, html_path=out, json_path=json_out, title=title)
    for name, result in results.items():
        headline = perspective_kind(name).headline
        print(f"{name:>13}: {result.message or headline(result.summary)}")
    return 0
