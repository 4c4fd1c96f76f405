"""``robotale fame check|split|run``: BPMN missions checked, split per robot and run."""

from __future__ import annotations

import json
import sys
from collections.abc import Mapping, Sequence
from functools import partial
from pathlib import Path
from typing import Any, TextIO

from robotale.errors import InputError, ModelError, require_range
from robotale.extras import require
from robotale.fame_runtime.bus import InProcessBus
from robotale.fame_runtime.check import Report, check
from robotale.fame_runtime.clock import SimClock
from robotale.fame_runtime.launch import (
    instance_counts,
    parse_assignments,
    refuse_duplicate_ids,
    robot_list,
    start_time,
)
from robotale.fame_runtime.library import Library
from robotale.fame_runtime.mission import Mission
from robotale.fame_runtime.model import Definitions, Problem
from robotale.fame_runtime.parser import ReadError, parse, parse_all
from robotale.fame_runtime.processes import run_processes
from robotale.fame_runtime.skills import load_skills
from robotale.fame_runtime.splitter import split, unbound_pools, write_split
from robotale.fame_runtime.tags import tag_line


def check_command(
    model: Path,
    *,
    library: Path | None = None,
    skills: str | None = None,
    world: Path | None = None,
    as_json: bool = False,
    out: TextIO | None = None,
) -> int:
    """Print the structure and QoS report -- every problem of reading and of deploying the
    file at once; with ``world`` (a simulation's world file) also what the model needs that
    the world's robots do not provide, call activities checked against the simulation's
    skills unless ``skills`` names others; with ``as_json`` as one JSON object. 1 when
    something is wrong."""
    out = out or sys.stdout
    if skills:
        names = load_skills(skills)
    else:
        names = _simulation_skills(model, world) if world is not None else {}
    try:
        definitions = parse_all(model)
    except ReadError as error:
        if not as_json:
            raise
        print(json.dumps(unreadable_json(model, error.problems), indent=2), file=out)
        return 1
    blocks = Library(library) if library else None
    report = check(definitions, skills=names, library=blocks)
    missing = []
    if world is not None and not definitions.problems:
        missing = _simulation_lacks(definitions, model, world, blocks)
    if as_json:
        print(json.dumps(report_json(report, missing), indent=2), file=out)
    else:
        print_report(report, out)
        print_lacks(missing, out)
    return 0 if report.ok and not missing else 1


def unreadable_json(model: Path, problems: Sequence[Problem]) -> dict[str, Any]:
    """The JSON report of a file that is no BPMN at all."""
    return {
        "file": str(model),
        "ok": False,
        "pools": [],
        "problems": [{**p.as_dict(), "pool": ""} for p in problems],
        "qos": [],
        "notes": [],
        "warnings": [],
        "lacks": [],
    }


def report_json(report: Report, missing: Sequence[str]) -> dict[str, Any]:
    """The report as data: what ``print_report`` prints, each problem with its element id,
    file, line, column (0: unknown) and sentence."""
    return {
        "file": report.file,
        "ok": report.ok and not missing,
        "pools": report.pools,
        "problems": [{**p.as_dict(), "pool": pool} for pool, p in report.found],
        "qos": [
            {
                "topic": pair.publisher.topic,
                "publisher": pair.publisher.describe(),
                "subscriber": pair.subscriber.describe(),
                "compatible": pair.compatible,
                "reasons": list(pair.reasons),
            }
            for pair in report.pairs
        ],
        "notes": report.notes,
        "warnings": report.warnings,
        "lacks": list(missing),
    }


def _simulation_skills(model: Path, world: Path) -> dict[str, Any]:
    # the simulator (0.8 s to import) only when a world is named
    from robotale.sim.run import skills_of
    from robotale.sim.worldspec import load_world

    return dict(skills_of(load_world(world, model)))


def _simulation_lacks(definitions, model: Path, world: Path, library: Library | None):
    # the simulator (0.8 s to import) only when a world is named
    from robotale.sim.provides import lacks
    from robotale.sim.worldspec import load_world

    return lacks(definitions, load_world(world, model), library)


def print_lacks(missing: Sequence[str], out: TextIO) -> None:
    """The "simulation lacks" section: every need of the model the robots do not meet."""
    if missing:
        print(f"simulation lacks: {len(missing)}", file=out)
        for sentence in missing:
            print(f"  {sentence}", file=out)


def print_report(report: Report, out: TextIO) -> None:
    print(f"{report.file}: pools {', '.join(report.pools)}", file=out)
    print(f"structure: {'ok' if not report.found else 'the engine cannot run'}", file=out)
    for pool, problem in report.found:
        where = f"{problem.file}:{problem.line}:" + (f"{problem.column}:" if problem.column else "")
        print(f"  {where} {pool + ': ' if pool else ''}{problem.sentence}", file=out)
    incompatible = sum(not p.compatible for p in report.pairs)
    print(
        f"QoS: {len(report.pairs)} publisher/subscriber pairs, {incompatible} incompatible",
        file=out,
    )
    for pair in report.pairs:
        verdict = "compatible" if pair.compatible else "INCOMPATIBLE: " + "; ".join(pair.reasons)
        print(
            f"  {pair.publisher.topic}: {pair.publisher.describe()} -> "
            f"{pair.subscriber.describe()}: {verdict}",
            file=out,
        )
    for note in report.notes:
        print(f"note: {note}", file=out)
    for warning in report.warnings:
        print(f"warning: {warning}", file=out)


def split_command(
    model: Path,
    *,
    robots: str | None = None,
    out_dir: Path | None = None,
    out: TextIO | None = None,
) -> int:
    """Print which robot runs which pool's process; with ``out_dir`` write one file each."""
    out = out or sys.stdout
    definitions = parse(model)
    assignments = split(definitions, robot_list(robots))
    for a in assignments:
        print(f"{a.robot}\t{a.robot_type}\t{a.process.describe()}", file=out)
    for pool in unbound_pools(definitions, assignments):
        print(f"# pool {pool}: no robot", file=out)
    if out_dir is not None:
        for path in write_split(assignments, out_dir):
            print(f"# wrote {path}", file=out)
    return 0


def run_command(
    model: Path,
    *,
    robots: str | None = None,
    skills: str | None = None,
    library: Path | None = None,
    until: float = 3600.0,
    latency: float = 0.0,
    assignments: Sequence[str] = (),
    start: str | None = None,
    bus: str = "inprocess",
    record: Path | None = None,
    out: TextIO | None = None,
    err: TextIO | None = None,
) -> int:
    """Run the mission, printing every tag as it happens (seconds since the start): on the
    in-process bus and a simulated clock, or (``bus="dds"``) one process per robot over DDS
    on the wall clock. 1 when a BPMN error went uncaught or robots were still working at
    ``until`` seconds."""
    out, err = out or sys.stdout, err or sys.stderr
    require_range(until, "--until", 0, unit=" seconds")
    require_range(latency, "--latency", 0, unit=" seconds")
    refuse_duplicate_ids(model)
    if bus == "dds":
        require("dds")  # before any robot's process is started
        # Cyclone DDS is an optional extra (robotale[dds]) and 0.9 s to import: --bus dds only
        from robotale.sim.live_recording import LiveRecording

        return run_processes(
            model,
            robots=robots,
            skills=skills,
            library=library,
            until=until,
            assignments=assignments,
            start=start,
            record=None if record is None else partial(LiveRecording, record),
            out=out,
            err=err,
        )
    if bus != "inprocess" or record is not None:
        raise InputError(_bus_problem(bus))
    names = load_skills(skills) if skills else None
    definitions = readable(model, names, library)
    begin = start_time(start)
    clock = SimClock(start=begin)
    mission = Mission(
        definitions,
        robots=robot_list(robots),
        clock=clock,
        bus=InProcessBus(
            clock, latency=latency, on_warning=lambda text: print(f"# warning: {text}", file=err)
        ),
        skills=names,
        library=library,
        tag_sink=lambda tag: print(tag_line(tag, begin), file=out),
        variables=parse_assignments(assignments),
    )
    for warning in definitions.warnings:  # as fame check prints them, before anything runs
        print(f"# warning: {warning}", file=err)
    mission.run(until=begin + until)
    return run_verdict(mission, begin, err)


def readable(model: Path, skills: Mapping[str, Any] | None, library: Path | None) -> Definitions:
    """The model, or one ModelError naming every problem of reading it together with what
    deploying its pools would refuse (as ``fame check`` lists them)."""
    definitions = parse_all(model)
    if not definitions.problems:
        return definitions
    report = check(definitions, skills=skills or {}, library=Library(library) if library else None)
    lines = "\n".join(
        f"{p.file}:{p.line}: {pool + ': ' if pool else ''}{p.sentence}" for pool, p in report.found
    )
    raise ModelError(f"{model}: {len(report.found)} problems:\n{lines}")


def _bus_problem(bus: str) -> str:
    if bus != "inprocess":
        return f"--bus {bus!r} is not one of inprocess, dds"
    return "--record needs --bus dds (a simulation records with robotale simulate)"


def run_verdict(mission: Mission, begin: float, err: TextIO) -> int:
    """Say how the run ended; 1 when an error went uncaught or robots are still working."""
    reached = mission.clock.now() - begin
    if mission.done:
        state = "done"
    elif mission.idle:
        state = "waiting for a timer"
    else:
        state = "still running"
    print(f"# {state} at {reached:.3f} s; {instance_counts(mission.engines)}", file=err)
    for place in mission.whereabouts():
        print(f"# {place}", file=err)
    for failure in mission.failures:
        print(f"# {failure}", file=err)
    return 1 if mission.failures or not mission.idle else 0
