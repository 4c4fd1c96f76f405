"""What launching a mission from the command line needs, whichever bus carries it: the robot
list, the start time, the variables set per robot, the duplicate-id check before anything runs
and the instance counts said at the end."""

from __future__ import annotations

import json
import time
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

from robotale.errors import InputError, ModelError
from robotale.fame_runtime.check import duplicate_ids
from robotale.fame_runtime.engine import Engine
from robotale.fame_runtime.timers import parse_date


def robot_list(text: str | None) -> list[str] | None:
    """``drone,tractor_1`` -> ["drone", "tractor_1"]."""
    return [r.strip() for r in text.split(",") if r.strip()] if text else None


def start_time(text: str | None) -> float:
    """The clock's start: now, or an ISO 8601 date-time (``timeDate`` timers fire on it)."""
    if text is None:
        return time.time()
    try:
        return parse_date(text)
    except ValueError as error:
        raise InputError(f"--start: {error}") from None


def parse_assignments(assignments: Sequence[str]) -> dict[str, dict[str, Any]]:
    """``drone.delay=10`` -> {"drone": {"delay": 10}} (values are JSON, else text)."""
    variables: dict[str, dict[str, Any]] = {}
    for text in assignments:
        target, equals, value = text.partition("=")
        robot, dot, name = target.partition(".")
        if not equals or not dot or not name.isidentifier():
            raise InputError(f"--set {text!r} is not ROBOT.NAME=VALUE (for example drone.delay=10)")
        try:
            parsed: Any = json.loads(value)
        except ValueError:
            parsed = value
        variables.setdefault(robot, {})[name] = parsed
    return variables


def refuse_duplicate_ids(model: Path) -> None:
    """The parser keeps one of the elements sharing an id, so a run would fail later with a
    misleading sentence (no start event ...): name the shared id instead, before anything runs."""
    shared = duplicate_ids(model)
    if shared:
        more = f" (and {len(shared) - 1} more)" if len(shared) > 1 else ""
        raise ModelError(f"{model}: {shared[0]}{more}")


def instance_counts(engines: Mapping[str, Engine]) -> str:
    """``instances completed: drone 1, tractor 0; failed: tractor 1`` (failed only when some
    instance failed)."""
    completed = ", ".join(f"{r} {e.completed}" for r, e in engines.items())
    failed = ", ".join(f"{r} {e.failed}" for r, e in engines.items() if e.failed)
    return f"instances completed: {completed}" + (f"; failed: {failed}" if failed else "")
