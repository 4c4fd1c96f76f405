"""The Mission page: one run replayed under one time cursor, over a map, the timeline, the
model's active elements, plots of any numeric field and the findings near the cursor; and the
data API it (and anyone) reads: a run's state at a moment and what happened in a window."""

from __future__ import annotations

import math
import time
from typing import Any

from flask import Blueprint, jsonify, render_template, request

from robotale.enhancement.mission import MissionRun
from robotale.enhancement.timeline import NO_ROBOT
from robotale.errors import InputError
from robotale.results.mission import (
    ModelMap,
    deviations,
    mission_site,
    model_map,
    stored_mission,
)
from robotale.results.replay import Replay
from robotale.results.site import stored_site
from robotale.webapp import pages
from robotale.webapp.model_store import StoredModel
from robotale.webapp.state import driver, state
from robotale.webapp.unstored import unstored

blueprint = Blueprint("mission", __name__)


@blueprint.get("/mission")
def page():
    context = pages.context("mission.page")
    model = _model(context["log"]) if context["log"] else None
    return render_template(
        "mission.html",
        case=request.args.get("case", ""),
        t=request.args.get("t", ""),
        model=model.id if model else "",
        **context,
    )


@blueprint.get("/api/mission/<log>/<case>")
def summary(log: str, case: str):
    """The run's length, robots, fields, activity instances, moments and site; with
    ``?since=`` seconds, only what may have changed from then on (see
    :meth:`MissionRun.summary`). With ``?known=`` a number of events, a live run holding that
    many is answered once it holds others, or after ``?wait=`` seconds (at most
    :data:`LONGEST_WAIT`): a page following the run hears of a tag as soon as it is stored,
    not at its next look."""
    since = _optional_seconds("since")
    known = request.args.get("known")
    replay = unstored(log)
    run = _run(log, case, replay)
    if known is not None and _live(log, replay):
        wait = min(max(_optional_seconds("wait", "to wait") or 0.0, 0.0), LONGEST_WAIT)
        replay, run = _grown(log, case, (replay, run), _count(known), time.monotonic() + wait)
    return jsonify({**run.summary(since), **_about(log, run, replay)})


#: seconds a look at a live run waits for it to grow at most; between two checks (the
#: monitor stores what it heard every tenth of a second: a check more often finds nothing)
LONGEST_WAIT, CHECK_EVERY = 30.0, 0.1


def _grown(
    log: str, case: str, now: tuple[Replay | None, MissionRun], known: int, until: float
) -> tuple[Replay | None, MissionRun]:
    """The live run (``now`` with its replay) once it holds other than ``known`` events, or
    as it is at ``until`` (monotonic): each check reads only what was stored since the
    last."""
    replay, run = now
    while len(run.events) == known and time.monotonic() < until:
        time.sleep(CHECK_EVERY)
        replay = unstored(log)
        if replay is None:  # the run was deleted meanwhile
            break
        run = _run(log, case, replay)
    return replay, run


def _count(text: str, name: str = "?known=") -> int:
    try:
        return int(text)
    except ValueError:
        raise InputError(f"{name} must be a whole number of events, not {text!r}.") from None


def _live(log: str, replay: Replay | None) -> bool:
    """Whether ``log`` is a live run (a replayed recording hides one of that name)."""
    return replay is not None and log not in state().replays


@blueprint.get("/api/mission/<log>/<case>/head")
def head(log: str, case: str):
    """The little the page draws its first moment with (the summary without the run's
    event times, instances and moments, which grow with the run)."""
    replay = unstored(log)
    run = _run(log, case, replay)
    return jsonify({**run.head(), **_about(log, run, replay)})


def _about(log: str, run: MissionRun, replay: Replay | None) -> dict[str, Any]:
    model = _model(log)
    return {
        "site": mission_site(_site(log, run, replay), run),
        "model": model.id if model else None,
        "live": _live(log, replay),
    }


@blueprint.get("/api/mission/<log>/<case>/state")
def state_at(log: str, case: str):
    """Every robot at ``?t=`` seconds since the run's start; with a model, the elements
    each robot is in and the flows taken so far. With ``?events=``, of a live run as it was
    kept when it holds that many events (see :func:`_holding`)."""
    t = _seconds("t", request.args.get("t"))
    replay = unstored(log, _holding())
    run = _run(log, case, replay)
    found: dict[str, Any] = run.state(t)
    elements = _elements(log, case, run.robots)
    if elements is not None:
        found["elements"] = elements.active(run, t)
        found["waiting"] = elements.waiting(run, t)
        found["deviations"] = elements.deviated(_deviations(log, run, kept=replay is None), t)
        found["flows"] = elements.flows_taken(run, t)
    return jsonify(found)


@blueprint.get("/api/mission/<log>/<case>/window")
def window(log: str, case: str):
    """The events, messages, positions and moments from ``?from=`` to ``?to=`` seconds. With
    ``?events=``, of a live run as it was kept when it holds that many events (see
    :func:`_holding`)."""
    start = _seconds("from", request.args.get("from"))
    end = _seconds("to", request.args.get("to"))
    run = _run(log, case, unstored(log, _holding()))
    return jsonify(run.window(start, end))


def _holding() -> int | None:
    """The number of events ``?events=`` gives, or None. A page following a live run sends
    the number its summary showed with the window and the state it asks next: they answer
    on the run that summary was made of, kept, rather than each make the run again of the
    tags stored in the meantime (at 20 robots some came between any two requests); the
    next look reads them."""
    text = request.args.get("events")
    return None if text is None else _count(text, "?events=")


@blueprint.get("/api/mission/<log>/<case>/series")
def series(log: str, case: str):
    """One numeric field (``?field=``) over the run, per robot."""
    run = _run(log, case)
    field = request.args.get("field", "")
    return jsonify({"field": field, "robots": run.series(field)})


_UNASKED = object()


def _run(log: str, case: str, replay: Any = _UNASKED) -> MissionRun:
    """The run from the replay named ``log`` this dashboard serves (a replay hides a stored
    log of the same name) or the live run of that name (``replay``, when the caller already
    looked for it), else from the stored log."""
    if replay is _UNASKED:
        replay = unstored(log)
    if replay is not None:
        return replay.run(case)
    return _stored(log, case)


def _stored(log: str, case: str) -> MissionRun:
    return stored_mission(driver(), state().logs, log, case)


def _site(log: str, run: MissionRun, replay: Replay | None) -> dict[str, Any] | None:
    if replay is not None:
        return replay.sites.get(run.case)
    return stored_site(driver(), log, run.case)


def _optional_seconds(name: str, what: str = "since the run's start") -> float | None:
    """The seconds ``?name=`` gives, or None when it is not given."""
    text = request.args.get(name)
    return None if text is None else _seconds(name, text, what)


def _seconds(name: str, text: str | None, what: str = "since the run's start") -> float:
    try:
        value = float(text) if text is not None else math.nan
    except ValueError:
        value = math.nan
    if not math.isfinite(value):
        raise InputError(f"?{name}= must be a number of seconds {what}, not {text!r}.")
    return value


def _model(log: str) -> StoredModel | None:
    """The model asked for (``?model=``), else the one linked to the log."""
    asked = request.args.get("model")
    models = state().models
    return models.get(asked) if asked else models.linked(log)


def _deviations(log: str, run: MissionRun, *, kept: bool) -> list[dict[str, Any]]:
    """The run's deviations from the log's model, kept for a stored log (a live run grows, a
    replay is in memory only)."""
    model = _model(log)
    if model is None:
        return []
    known = [robot for robot in run.robots if robot != NO_ROBOT]
    if not kept:
        return deviations(model.path, run, known)
    return state().logs.missions.get(
        (log, "deviations", model.id, run.case), lambda: deviations(model.path, run, known)
    )


def _elements(log: str, case: str, robots: list[str]) -> ModelMap | None:
    model = _model(log)
    if model is None:
        return None
    known = [robot for robot in robots if robot != NO_ROBOT]
    return state().logs.missions.get(
        (log, "model", model.id, case), lambda: model_map(model.path, known)
    )
