"""What the Findings, Perspectives and Timeline pages show of a stored log, as JSON computed once
per build of the log (:meth:`LogData.result`); storing a log prepares all of it in the
background, so the first visit after that computes nothing."""

from __future__ import annotations

import json
import math
from collections.abc import Callable, Sequence
from functools import partial
from typing import Any

from neo4j import Driver
from neo4j.exceptions import DriverError, Neo4jError

from robotale.enhancement.findings import find, trusted_first
from robotale.enhancement.registry import page_names, perspective_kind
from robotale.enhancement.timeline import case_timeline, run_list
from robotale.errors import InputError, RobotaleError
from robotale.results.logdata import LogData, first_key, log_info
from robotale.results.mission import stored_mission, stored_slow_limits


def parse_delay(text: str | None) -> float | None:
    """The ``delay`` argument of a request: seconds above which a message is delayed (missing
    or empty: the default rule)."""
    return parse_seconds(text, "the delay")


def parse_seconds(text: str | None, what: str) -> float | None:
    """A request's argument ``what`` of seconds, 0 or more (None when missing or empty)."""
    if text is None or not text.strip():
        return None
    try:
        seconds = float(text)
    except ValueError:
        seconds = math.nan
    if not math.isfinite(seconds) or seconds < 0:
        raise InputError(f"{what} {text!r} is not a number of seconds of 0 or more.")
    return seconds


def _delay_key(delay: float | None) -> tuple[str, ...]:
    return () if delay is None else ("delay", repr(delay))


def stored_findings(driver: Driver, logs: LogData, name: str, delay: float | None = None) -> bytes:
    """The answers for the stored log ``name`` and its runs (case, start, duration); a message
    is delayed above ``delay`` seconds (else by the default rule)."""

    def compute() -> dict[str, Any]:
        result = find(logs.analysis(driver, name), delay_threshold=delay)
        runs = result.runs.reindex(columns=["case", "start", "duration"])
        return {**result.to_dict(), "runs": runs.to_dict(orient="records")}

    return logs.result(driver, name, ("findings", *_delay_key(delay)), compute)


def stored_perspective(
    driver: Driver,
    logs: LogData,
    name: str,
    which: str,
    activity: str | None = None,
    robot: str | None = None,
    delay: float | None = None,
) -> bytes:
    """The perspective ``which`` of the whole log, or of one activity (and robot); for the
    communication perspective, a message is delayed above ``delay`` seconds if given."""
    kind = perspective_kind(which)
    options = kind.taken({"delay_threshold": delay})

    def compute() -> dict[str, Any]:
        analysis = logs.analysis(driver, name)
        result = kind.compute(analysis, activity=activity, robot=robot, **options)
        if which == "bottlenecks" and result.has_data:
            # the same order as the Findings page: effects that may be chance come last
            result.tables["bottlenecks"] = trusted_first(result.tables["bottlenecks"])
        return result.to_dict()

    focus: tuple[str, ...] = (
        ("activity", activity or "", "robot", robot or "") if activity or robot else ()
    )
    if options:
        focus += _delay_key(delay)
    return logs.result(driver, name, ("perspective", which, *focus), compute)


def stored_runs(driver: Driver, logs: LogData, name: str) -> bytes:
    """The log's runs in start order, for the Timeline page's run picker."""
    return logs.result(
        driver,
        name,
        ("runs",),
        lambda: {"runs": run_list(logs.frame(driver, name)).to_dict(orient="records")},
    )


def stored_timeline(driver: Driver, logs: LogData, name: str, case: str) -> bytes:
    """The timeline of the run ``case`` (the first run when empty): kept once per run, so
    the Timeline page's first run and the Mission page's named run share it."""
    case = case or _first_run(driver, logs, name)
    return logs.result(
        driver,
        name,
        ("timeline", case),
        lambda: case_timeline(logs.frame(driver, name), case).to_dict(),
    )


def _first_run(driver: Driver, logs: LogData, name: str) -> str:
    """The log's first run (the kept run list's), "" when it has none."""
    runs = json.loads(stored_runs(driver, logs, name))["runs"]
    return str(runs[0]["case"]) if runs else ""


def perspectives_graph(driver: Driver, logs: LogData, name: str) -> dict[str, Any]:
    """The class graph the Perspectives page draws beside its sections: by activity and
    robot when the log has robots as entities (``perspectives.js`` asks for the same)."""
    types = log_info(driver, name).get("entityTypes") or []
    return logs.class_graph(driver, name, first_key(types))


#: what :func:`prepare` reports after each step: steps done, steps in all, the step done
Progress = Callable[[int, int, str], None]
#: the steps of :func:`prepare` each page shows the results of, by page
PAGE_STEPS: dict[str, tuple[str, ...]] = {
    "findings": ("findings",),
    "perspectives": ("class graph", *page_names()),
    "timeline": ("runs", "timeline"),
}


def prepare(
    driver: Driver,
    logs: LogData,
    name: str,
    progress: Progress | None = None,
    first: Sequence[str] = (),
) -> None:
    """Compute what the pages show first of ``name`` (after it was stored): the findings, the
    perspectives of the whole log, the class graph beside them, the runs and the first run's
    timeline, what counts as a slow activity on the Mission page and its first run, the steps
    named in ``first`` before the others (those of a page waiting for them); ``progress``
    hears of each step as it is done."""
    steps: list[tuple[str, Callable[[], object]]] = [
        ("findings", lambda: stored_findings(driver, logs, name)),
        ("class graph", lambda: perspectives_graph(driver, logs, name)),
    ]
    steps += [
        (which, partial(stored_perspective, driver, logs, name, which)) for which in page_names()
    ]
    steps += [
        ("runs", lambda: stored_runs(driver, logs, name)),
        ("timeline", lambda: stored_timeline(driver, logs, name, "")),
        ("slow limits", lambda: stored_slow_limits(driver, logs, name)),
        ("mission", lambda: stored_mission(driver, logs, name, _first_run(driver, logs, name))),
    ]
    steps.sort(key=lambda named: named[0] not in first)  # stable: the others keep their order
    for done, (what, step) in enumerate(steps, start=1):
        try:
            step()
        except RobotaleError:  # the page says why when it is visited; the rest is still useful
            pass
        except (Neo4jError, DriverError, OSError):  # Neo4j or the log went away: a visit says so
            return
        if progress is not None:
            progress(done, len(steps), what)
