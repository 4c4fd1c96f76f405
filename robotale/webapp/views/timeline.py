"""The Timeline page: one run, a lane per robot with its activities as bars, the messages
between robots as arrows (lost ones marked) and each robot's battery as a line."""

from __future__ import annotations

from flask import Blueprint, Response, render_template, request

from robotale.results.findings import stored_runs, stored_timeline
from robotale.webapp import pages
from robotale.webapp.state import driver, state
from robotale.webapp.unstored import unstored

blueprint = Blueprint("timeline", __name__)


@blueprint.get("/timeline")
def page():
    return render_template(
        "timeline.html", case=request.args.get("case", ""), **pages.context("timeline.page")
    )


@blueprint.get("/api/timeline/runs")
def runs():
    """The log's runs in start order, for the run picker."""
    name = request.args.get("log", "")
    replay = unstored(name)
    if replay is not None:  # a replayed recording (hiding a stored log) or a live run
        return Response(replay.runs_json(), mimetype="application/json")
    data = stored_runs(driver(), state().logs, name)
    return Response(data, mimetype="application/json")


@blueprint.get("/api/timeline")
def timeline():
    """One run's timeline (the first run when none is named)."""
    name, case = request.args.get("log", ""), request.args.get("case", "")
    replay = unstored(name)
    if replay is not None:
        return Response(replay.timeline_json(case), mimetype="application/json")
    return Response(
        stored_timeline(driver(), state().logs, name, case), mimetype="application/json"
    )
