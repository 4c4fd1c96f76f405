"""The Timeline page: one run, a lane per robot with its activities as bars, the messages
between robots as arrows (lost ones marked) and each robot's battery as a line."""

from __future__ import annotations

from flask import Blueprint, jsonify, render_template, request

from robotale.discovery.graph import json_ready
from robotale.enhancement.timeline import case_timeline, run_list
from robotale.webapp import pages
from robotale.webapp.state import driver, state

blueprint = Blueprint("timeline", __name__)


@blueprint.get("/timeline")
def page():
    return render_template(
        "timeline.html", case=request.args.get("case", ""), **pages.context("timeline.page")
    )


@blueprint.get("/api/timeline/runs")
def runs():
    """The log's runs in start order, for the run picker."""
    frame = state().logs.frame(driver(), request.args.get("log", ""))
    return jsonify(runs=json_ready(run_list(frame).to_dict(orient="records")))


@blueprint.get("/api/timeline")
def timeline():
    """One run's timeline (the first run when none is named)."""
    frame = state().logs.frame(driver(), request.args.get("log", ""))
    case = request.args.get("case") or _first_run(frame)
    return jsonify(case_timeline(frame, case).to_dict())


def _first_run(frame) -> str:
    runs = run_list(frame)
    return str(runs["case"].iloc[0]) if not runs.empty else ""
