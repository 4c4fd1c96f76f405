"""Handlers of the ``discover`` command group (the parser lives in :mod:`robotale.cli`)."""

from __future__ import annotations

import argparse
import json
from pathlib import Path

import pandas as pd

from robotale.errors import InputError


def read_event_log(args: argparse.Namespace) -> pd.DataFrame:
    """The event log a command names: a CSV/XES file (``LOG``, with ``--map`` and
    ``--case-column``) or, with ``--log NAME``, a log stored in Neo4j."""
    if getattr(args, "log_name", None):
        from robotale.discovery.ekg import read_stored_log

        return read_stored_log(args.log_name)
    if not getattr(args, "log", None):
        raise InputError("name an event log: a CSV or XES file, or --log NAME for a stored one.")
    from robotale.ingest.readers import read_log

    return read_log(args.log, mapping=mapping(args.map or []), case=args.case_column)


def mapping(pairs: list[str]) -> dict[str, str]:
    """``["Zeit=time", ...]`` as ``{"Zeit": "time"}``."""
    result = {}
    for pair in pairs:
        column, sep, field = pair.partition("=")
        if not sep or not column.strip() or not field.strip():
            raise InputError(f"--map {pair!r} is not COLUMN=FIELD (for instance Zeit=time).")
        result[column.strip()] = field.strip()
    return result


def values(lists: list[str] | None) -> tuple[str, ...]:
    """Repeated and comma-separated option values as one tuple."""
    return tuple(v.strip() for item in lists or [] for v in item.split(",") if v.strip())


def discover_dfg(args: argparse.Namespace) -> int:
    from robotale.discovery.dfg import discover_dfg as discover
    from robotale.discovery.filters import LogFilter

    if args.svg:
        from robotale.discovery.render import require_dot

        require_dot()  # before any work, so a missing Graphviz costs nothing
    selection = LogFilter(
        cases=values(args.case),
        robots=values(args.robot),
        robot_types=values(args.robot_type),
        activities=values(args.activity),
        start=args.since,
        end=args.until,
    )
    graph = discover(read_event_log(args), selection)
    return emit_graph(graph, args)


def emit_graph(graph, args: argparse.Namespace) -> int:
    """Write the graph as JSON (``--out``, else to standard output) and SVG (``--svg``)."""
    from robotale.discovery.output import write_texts
    from robotale.discovery.render import graph_to_svg

    outputs = []
    if args.out:
        outputs.append((Path(args.out), graph.to_json()))
    if args.svg:
        outputs.append((Path(args.svg), graph_to_svg(graph, labels=args.labels)))
    write_texts(outputs)
    if not args.out:
        print(graph.to_json())
        return 0
    activities = sum(1 for node in graph.nodes if node.kind == "activity")
    written = " and ".join(str(path) for path, _ in outputs)
    print(f"{graph.kind.upper()}: {activities} activities, {len(graph.edges)} edges -> {written}")
    return 0


def discover_conformance(args: argparse.Namespace) -> int:
    from robotale.discovery.conformance import check_conformance
    from robotale.discovery.output import write_texts

    report = check_conformance(read_event_log(args), args.model, library=args.library)
    if args.json:
        write_texts([(Path(args.json), json.dumps(report.to_dict(), indent=2))])
    print(report.robots.to_string(index=False, float_format=lambda v: f"{v:.3f}"))
    if report.deviations.empty:
        print("No deviations: every robot did what its process allows.")
    else:
        print("\nDeviations:")
        print(report.deviations.to_string(index=False))
    if not report.outside.empty:
        print("\nMessages the processes do not model (sent or received by skills), not replayed:")
        print(report.outside.to_string(index=False))
    return 0


def discover_ekg(args: argparse.Namespace) -> int:
    from robotale.discovery.ekg import discover_ekg as discover

    if args.svg:
        from robotale.discovery.render import require_dot

        require_dot()
    entities = values([args.entities]) if args.entities else None
    graph = discover(args.log_name, args.aggregate, entities)
    return emit_graph(graph, args)
