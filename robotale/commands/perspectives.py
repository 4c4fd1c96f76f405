"""``robotale perspectives``: spatial, communication, battery and performance perspectives."""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path

from robotale.commands.logsource import read_event_log
from robotale.enhancement.report import all_perspectives, write_report
from robotale.enhancement.spatial import Field
from robotale.errors import InputError, require_range


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
) -> int:
    """The perspectives of a log (a file or ``log_name``) as HTML (``out``) and/or JSON."""
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
    results = all_perspectives(events, activity=activity, robot=robot, field=area, **options)
    title = f"robotale perspectives: {log_name or Path(log or '').name}"
    write_report(results, html_path=out, json_path=json_out, title=title)
    for name, result in results.items():
        print(f"{name:>13}: {result.message or _headline(name, result.summary)}")
    return 0


def _headline(name: str, summary: dict) -> str:
    if name == "spatial":
        covered = summary.get("field", {}).get("covered_fraction")
        field = f", {covered:.0%} of the field covered" if covered is not None else ""
        return f"{summary['positions']} positions{field}"
    if name == "communication":
        return (
            f"{summary['messages']} messages, {summary['received']} received, "
            f"{summary['lost']} lost, {summary.get('unobserved', 0)} not observed as received, "
            f"{summary['resends']} resends "
            f"({summary.get('resends_new_id', 0)} under a new id), "
            f"{summary.get('delayed', 0)} delayed, {summary.get('channels', 0)} channels"
        )
    if name == "battery":
        per_run = summary.get("used_per_run")
        used = (
            summary.get("battery_levels")
            if not per_run
            else "used per run: " + ", ".join(f"{r} {u:.1f}%" for r, u in per_run.items())
        )
        return f"{summary['low_battery_events']} low-battery events; {used}"
    if name == "performance":
        share = summary.get("waiting_share")
        waiting = "" if share is None else f", robots wait {share:.0%} of their time"
        return (
            f"{summary['cases']} cases, {summary.get('variants', 0)} variants{waiting}, "
            f"slowest transition {summary['slowest_transition']}"
        )
    return f"first: {summary['first']}"
