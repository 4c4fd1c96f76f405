"""``robotale discover dfg|ekg|conformance``: process models from an event log."""

from __future__ import annotations

import json
from collections.abc import Sequence
from pathlib import Path

from robotale.discovery.binding import bind
from robotale.discovery.bpmn_writer import lacking_skills, write_bpmn
from robotale.discovery.collaboration import discover_collaboration
from robotale.discovery.conformance import check_conformance
from robotale.discovery.dfg import discover_dfg
from robotale.discovery.ekg import discover_ekg
from robotale.discovery.filters import LogFilter
from robotale.discovery.graph import ProcessGraph
from robotale.discovery.model_diff import diff_models, marked_model
from robotale.discovery.output import write_texts
from robotale.discovery.render import graph_to_svg, require_dot
from robotale.discovery.repeats import constant_repeats
from robotale.discovery.signal_starts import started_on_signals
from robotale.discovery.trigger_times import timed_triggers
from robotale.errors import InputError
from robotale.results.eventlogs import read_event_log


def dfg_command(
    log: Path | None = None,
    *,
    log_name: str | None = None,
    mapping: Sequence[str] = (),
    case_column: str | None = None,
    case_gap: str | None = None,
    cases: Sequence[str] | None = None,
    robots: Sequence[str] | None = None,
    robot_types: Sequence[str] | None = None,
    activities: Sequence[str] | None = None,
    since: str | None = None,
    until: str | None = None,
    out: Path | None = None,
    svg: Path | None = None,
    labels: str = "frequency",
) -> int:
    """The directly-follows graph of a log, filtered; JSON to ``out`` (else printed), SVG."""
    if svg:
        require_dot()  # before any work, so a missing Graphviz costs nothing
    selection = _selection(cases, robots, robot_types, activities, since, until)
    events = read_event_log(
        log, log_name=log_name, mapping=mapping, case_column=case_column, case_gap=case_gap
    )
    return emit_graph(discover_dfg(events, selection), out=out, svg=svg, labels=labels)


def bpmn_command(
    log: Path | None = None,
    *,
    out: Path,
    log_name: str | None = None,
    mapping: Sequence[str] = (),
    case_column: str | None = None,
    case_gap: str | None = None,
    cases: Sequence[str] | None = None,
    robots: Sequence[str] | None = None,
    robot_types: Sequence[str] | None = None,
    activities: Sequence[str] | None = None,
    since: str | None = None,
    until: str | None = None,
    noise: float = 0.0,
    bind_to: Path | None = None,
) -> int:
    """The robots' collaboration as a BPMN file with its diagram (``out``); with ``bind_to``
    (a driving model) each element runs what its same-named element there runs."""
    if not 0.0 <= noise <= 1.0:
        raise InputError(f"--noise must lie between 0 and 1, not {noise:g}.")
    if bind_to is not None and not Path(bind_to).is_file():
        raise InputError(f"--bind {bind_to}: there is no such file")
    selection = _selection(cases, robots, robot_types, activities, since, until)
    events = read_event_log(
        log, log_name=log_name, mapping=mapping, case_column=case_column, case_gap=case_gap
    )
    collaboration = discover_collaboration(events, selection, noise=noise)
    if bind_to is not None:  # to run: robots waiting for orders start an instance per order
        collaboration = started_on_signals(collaboration, events, selection, noise=noise)
    bindings = bind([pool.name for pool in collaboration.pools], bind_to)
    if bind_to is not None:
        bindings.timers = timed_triggers(collaboration, events, bindings, selection)
        bindings.repeats = constant_repeats(collaboration, events, selection)
    write_texts([(out, write_bpmn(collaboration, bindings))])
    for pool in collaboration.pools:
        robots_text = ", ".join(pool.robots)
        handlers = ", ".join(h.name for h in pool.handlers) or "none"
        started = f"; an instance per {pool.starts_on}" if pool.starts_on else ""
        print(f"pool {pool.name} ({robots_text}): event sub-processes on {handlers}{started}")
    for sentence in lacking_skills(collaboration, bindings):
        print(sentence)
    for signal in collaboration.signals.values():
        print(f"signal {signal.name}: {signal.text()}")
    print(f"-> {out}")
    return 0


def _selection(cases, robots, robot_types, activities, since, until) -> LogFilter:
    return LogFilter(
        cases=values(cases),
        robots=values(robots),
        robot_types=values(robot_types),
        activities=values(activities),
        start=since,
        end=until,
    )


def ekg_command(
    log_name: str,
    *,
    aggregate: str | None = None,
    entities: str | None = None,
    out: Path | None = None,
    svg: Path | None = None,
    labels: str = "frequency",
) -> int:
    """The class graph Neo4j aggregates for the stored log ``log_name``."""
    if svg:
        require_dot()
    types = values([entities]) if entities else None
    graph = discover_ekg(log_name, aggregate, types)
    return emit_graph(graph, out=out, svg=svg, labels=labels)


def conformance_command(
    log: Path | None = None,
    *,
    model: Path,
    library: Path | None = None,
    json_out: Path | None = None,
    log_name: str | None = None,
    mapping: Sequence[str] = (),
    case_column: str | None = None,
    case_gap: str | None = None,
) -> int:
    """Each robot's runs replayed against its pool of the BPMN collaboration ``model``."""
    events = read_event_log(
        log, log_name=log_name, mapping=mapping, case_column=case_column, case_gap=case_gap
    )
    report = check_conformance(events, model, library=library)
    if json_out:
        write_texts([(json_out, json.dumps(report.to_dict(), indent=2))])
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


def emit_graph(
    graph: ProcessGraph, *, out: Path | None, svg: Path | None, labels: str = "frequency"
) -> int:
    """Write the graph as JSON (``out``, else to standard output) and SVG (``svg``)."""
    outputs = []
    if out:
        outputs.append((out, graph.to_json()))
    if svg:
        outputs.append((svg, graph_to_svg(graph, labels=labels)))
    write_texts(outputs)
    if not out:
        print(graph.to_json())
        return 0
    activities = sum(1 for node in graph.nodes if node.kind == "activity")
    written = " and ".join(str(path) for path, _ in outputs)
    print(f"{graph.kind.upper()}: {activities} activities, {len(graph.edges)} edges -> {written}")
    return 0


def values(lists: Sequence[str] | None) -> tuple[str, ...]:
    """Repeated and comma-separated option values as one tuple."""
    return tuple(v.strip() for item in lists or [] for v in item.split(",") if v.strip())


def diff_command(
    driving: Path, discovered: Path, *, json_out: Path | None = None, out: Path | None = None
) -> int:
    """What the robots never used of the ``driving`` model and what they did beyond it
    (``discovered``): printed, as JSON (``json_out``) and as the driving model marked
    (``out``)."""
    found = diff_models(driving, discovered)
    outputs = []
    if out is not None:  # first: a model without a diagram writes nothing
        outputs.append((out, marked_model(driving, found).decode("utf-8")))
    if json_out is not None:
        outputs.append((json_out, json.dumps(found.to_dict(), indent=2)))
    write_texts(outputs)
    print(found.text())
    return 0
