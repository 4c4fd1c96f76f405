"""``robotale report``: the answers to an analyst's five questions about a log, printed, and
as HTML (with the runs' timelines) and/or JSON."""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path

from robotale.enhancement.findings import find
from robotale.enhancement.findings_report import findings_text, write_findings
from robotale.errors import require_range
from robotale.results.eventlogs import read_event_log


def report_command(
    log: Path | None = None,
    *,
    log_name: str | None = None,
    mapping: Sequence[str] = (),
    case_column: str | None = None,
    case_gap: str | None = None,
    out: Path | None = None,
    json_out: Path | None = None,
    threshold: float | None = None,
    delay: float | None = None,
) -> int:
    """The findings of a log (a file or ``log_name``): printed, and written to ``out`` (HTML)
    and/or ``json_out``."""
    if threshold is not None:
        require_range(threshold, "--threshold", 0, 100, unit=" percent")
    if delay is not None:
        require_range(delay, "--delay", 0, unit=" seconds")
    events = read_event_log(
        log, log_name=log_name, mapping=mapping, case_column=case_column, case_gap=case_gap
    )
    options = {} if threshold is None else {"threshold": threshold}
    findings = find(events, delay_threshold=delay, **options)
    title = f"robotale findings: {log_name or Path(log or '').name}"
    write_findings(findings, events, html_path=out, json_path=json_out, title=title)
    print(findings_text(findings))
    return 0
