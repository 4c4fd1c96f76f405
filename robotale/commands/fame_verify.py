"""``robotale fame verify``: model analysis of a mission before anything runs."""

from __future__ import annotations

import json
import sys
from pathlib import Path
from typing import TextIO

from robotale.errors import RobotaleError, require_range
from robotale.fame_runtime.launch import refuse_duplicate_ids, robot_list
from robotale.fame_runtime.library import Library
from robotale.fame_runtime.parser import parse
from robotale.fame_runtime.skills import load_skills
from robotale.fame_runtime.tags import tag_line
from robotale.fame_runtime.verify import MAX_STATES, TIMEOUT, Verdict, verify

#: exit statuses: no finding, a finding, input that cannot be verified
CLEAN, FOUND, BAD_INPUT = 0, 1, 2


def verify_command(
    model: Path,
    *,
    robots: str | None = None,
    skills: str | None = None,
    library: Path | None = None,
    outside: str | None = None,
    max_states: int | None = None,
    timeout: float | None = None,
    as_json: bool | None = None,
    out: TextIO | None = None,
    err: TextIO | None = None,
) -> int:
    """Explore the mission's states and print every finding with a shortest trace; 1 on a
    finding, 0 on none, 2 when the model or an option cannot be used."""
    out, err = out or sys.stdout, err or sys.stderr
    try:
        limit = int(
            require_range(MAX_STATES if max_states is None else max_states, "--max-states", 1)
        )
        seconds = require_range(
            TIMEOUT if timeout is None else timeout, "--timeout", 0, unit=" seconds"
        )
        refuse_duplicate_ids(model)
        definitions = parse(model)
        verdict = verify(
            definitions,
            robots=robot_list(robots),
            skills=load_skills(skills) if skills else (),
            library=Library(library if library is not None else model.parent),
            outside=robot_list(outside) or (),
            max_states=limit,
            timeout=seconds,
        )
    except RobotaleError as error:
        print(f"robotale: {error}", file=err)
        return BAD_INPUT
    if as_json:
        json.dump(verdict.as_dict(), out, indent=2)
        print(file=out)
    else:
        print_verdict(verdict, model, out)
    return FOUND if verdict.findings else CLEAN


def print_verdict(verdict: Verdict, model: Path, out: TextIO) -> None:
    """The summary line, then each finding with its trace as tag lines (step numbers as
    stamps)."""
    explored = f"{verdict.states} states, {verdict.steps} steps explored in {verdict.seconds:.2f} s"
    bound = f"; stopped early: {verdict.bound}" if verdict.bound else ""
    print(f"{model}: robots {', '.join(verdict.robots)}; {explored}{bound}", file=out)
    if verdict.bound:
        print(
            "note: the exploration is incomplete: elements never reached are not listed, and "
            "a loop without exit is reported only inside the explored states",
            file=out,
        )
    for abstraction in verdict.abstractions:
        print(f"note: {abstraction}", file=out)
    print(f"findings: {len(verdict.findings)}", file=out)
    for finding in verdict.findings:
        print(f"{finding.kind}: {finding.sentence}", file=out)
        for tag in finding.trace:
            print(f"  {tag_line(tag)}", file=out)
