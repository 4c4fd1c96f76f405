"""The Discover page: the DFG with filters and the aggregated EKG with an aggregation selector
per entity type (thesis figures 7.2 and 7.6), drawn as an interactive graph."""

from __future__ import annotations

from flask import Blueprint, jsonify, render_template, request

from robotale.discovery import LogFilter, discover_dfg
from robotale.ekg.logs import log_values
from robotale.results.logdata import log_info
from robotale.webapp import pages
from robotale.webapp.state import driver, state

blueprint = Blueprint("discover", __name__)

#: the filters, named as in the query string and as Event properties
FILTERS = ("case", "robot", "robot_type", "activity")


@blueprint.get("/discover")
def page():
    return render_template("discover.html", **pages.context("discover.page"))


def chosen_log() -> str:
    return request.args.get("log", "")


@blueprint.get("/api/discover/values")
def values():
    """What the filters and the aggregation selector offer for this log."""
    name = chosen_log()
    info = log_info(driver(), name)
    found = log_values(driver(), name)
    offered = {key: sorted(str(v) for v in found[key]) for key in FILTERS if found[key]}
    return jsonify(
        filters=offered,
        entity_types=info.get("entityTypes") or [],
        class_types=info.get("classTypes") or [],
        events=found["events"],
    )


@blueprint.get("/api/discover/dfg")
def dfg():
    selection = LogFilter(
        cases=request.args.getlist("case"),
        robots=request.args.getlist("robot"),
        robot_types=request.args.getlist("robot_type"),
        activities=request.args.getlist("activity"),
        # a time that is no time is one sentence (LogFilter), never a filter silently dropped
        start=request.args.get("since") or None,
        end=request.args.get("until") or None,
    )
    return jsonify(discover_dfg(state().logs.frame(driver(), chosen_log()), selection).to_dict())


@blueprint.get("/api/discover/ekg")
def ekg():
    """The class graph aggregated by activity and the entity types in ``by``, with the flow
    of the entity types in ``edges`` (all of the log's when none is named)."""
    key = ["activity", *request.args.getlist("by")]
    edges = request.args.getlist("edges") or None
    return jsonify(state().logs.class_graph(driver(), chosen_log(), key, edges))
