"""``robotale aggregate``: run an aggregation specification on a stored log, or undo steps."""

from __future__ import annotations

import json
from pathlib import Path

from robotale.ekg.connection import session_driver
from robotale.ekg.spec import read_spec
from robotale.ekg.steps import StepResult, list_steps, run_spec, undo
from robotale.errors import InputError

#: what ``--undo`` without a step number means
LAST = "last"


def aggregate_command(
    log_name: str,
    *,
    spec: Path | None = None,
    undo_step: str | None = None,
    steps: bool = False,
    as_json: bool = False,
) -> int:
    """Run ``spec`` on ``log_name`` (each step's counts printed), undo steps, or list them."""
    if sum(map(bool, (spec, undo_step, steps))) != 1:
        raise InputError("Give one of --spec FILE, --undo [STEP] or --steps.")
    if spec is not None:
        parsed = read_spec(spec)  # before connecting: a bad file costs nothing
        with session_driver() as driver:
            results = run_spec(driver, log_name, parsed)
        _show(results, as_json)
        return 0
    with session_driver() as driver:
        if steps:
            rows = list_steps(driver, log_name)
            print(json.dumps(rows, indent=2) if as_json else _table(rows))
            return 0
        undone = undo(driver, log_name, _step_number(undo_step))
    if not undone:
        print(f"The log {log_name!r} has no aggregation steps to undo.")
    else:
        print(f"Undid aggregation step{'s' if len(undone) > 1 else ''} "
              f"{', '.join(map(str, undone))} of {log_name!r}.")  # fmt: skip
    return 0


def _step_number(text: str | None) -> int | None:
    if text in (None, LAST):
        return None
    try:
        number = int(str(text))
    except ValueError:
        number = 0
    if number < 1:
        raise InputError(f"--undo takes a step number (1, 2 ...), not {text!r}.")
    return number


def _show(results: list[StepResult], as_json: bool) -> None:
    if as_json:
        print(json.dumps([r.to_dict() for r in results], indent=2))
        return
    print(f"{'step':>4} {'aggregates':>10} {'events':>19} {'entities':>19} {'seconds':>8}")
    for r in results:
        events = f"{r.initial_events:,} -> {r.final_events:,}"
        entities = f"{r.initial_entities:,} -> {r.final_entities:,}"
        print(f"{r.step:>4} {r.aggregates:>10,} {events:>19} {entities:>19} {r.seconds:>8.2f}")


def _table(rows: list[dict[str, object]]) -> str:
    if not rows:
        return "No aggregation steps."
    return "\n".join(
        f"{row['step']:>3}  {row['status']:<9} {row['aggregates'] or 0:>8,} aggregates  "
        f"{row['spec']}"
        for row in rows
    )
