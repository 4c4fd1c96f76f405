"""Handler of the ``perspectives`` command (the parser lives in :mod:`robotale.cli`)."""

from __future__ import annotations

import argparse
from pathlib import Path

from robotale.discovery.commands import read_event_log
from robotale.errors import InputError


def perspectives(args: argparse.Namespace) -> int:
    from robotale.enhancement.report import all_perspectives, write_report
    from robotale.enhancement.spatial import Field

    if not args.out and not args.json:
        raise InputError("say where the report goes: --out report.html and/or --json report.json.")
    field = Field.parse(args.field) if args.field else None
    log = read_event_log(args)
    results = all_perspectives(
        log, activity=args.activity, robot=args.robot, field=field, threshold=args.threshold
    )
    title = f"robotale perspectives: {args.log_name or Path(args.log).name}"
    write_report(
        results,
        html_path=Path(args.out) if args.out else None,
        json_path=Path(args.json) if args.json else None,
        title=title,
    )
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
            f"{summary['lost']} lost, {summary['resends']} resends"
        )
    if name == "battery":
        return f"{summary['low_battery_events']} low-battery events"
    if name == "performance":
        return f"{summary['cases']} cases, slowest transition {summary['slowest_transition']}"
    return f"first: {summary['first']}"
