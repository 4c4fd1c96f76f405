"""The Discover page: the DFG with filters and the aggregated EKG with an aggregation selector
per entity type (thesis figures 7.2 and 7.6), drawn as an interactive graph."""

from __future__ import annotations

from flask import Blueprint, jsonify, render_template, request

from robotale.ingest import schema
from robotale.webapp import pages
from robotale.webapp.logdata import log_frame, log_info
from robotale.webapp.neo4j_access import driver

blueprint = Blueprint("discover", __name__)

#: filter name in the query string -> column of the log
FILTERS = {
    "case": schema.CASE,
    "robot": schema.ROBOT,
    "robot_type": schema.ROBOT_TYPE,
    "activity": schema.ACTIVITY,
}


@blueprint.get("/discover")
def page():
    return render_template("discover.html", **pages.context("discover.page"))


def chosen_log() -> str:
    return request.args.get("log", "")


@blueprint.get("/api/discover/values")
def values():
    """What the filters and the aggregation selector offer for this log."""
    name = chosen_log()
    log = log_frame(name)
    offered = {
        key: sorted(log[column].dropna().astype(str).unique().tolist())
        for key, column in FILTERS.items()
        if column in log.columns
    }
    info = log_info(name)
    return jsonify(
        filters=offered,
        entity_types=info.get("entityTypes") or [],
        class_types=info.get("classTypes") or [],
        events=len(log),
    )


@blueprint.get("/api/discover/dfg")
def dfg():
    from robotale.discovery import LogFilter, discover_dfg

    selection = LogFilter(
        cases=request.args.getlist("case"),
        robots=request.args.getlist("robot"),
        robot_types=request.args.getlist("robot_type"),
        activities=request.args.getlist("activity"),
    )
    return jsonify(discover_dfg(log_frame(chosen_log()), selection).to_dict())


@blueprint.get("/api/discover/ekg")
def ekg():
    """The class graph aggregated by activity and the entity types in ``by``, with the flow
    of the entity types in ``edges`` (all of the log's when none is named)."""
    from robotale.discovery import discover_ekg

    key = ["activity", *request.args.getlist("by")]
    edges = request.args.getlist("edges") or None
    graph = discover_ekg(chosen_log(), key, edges, driver=driver())
    return jsonify(graph.to_dict())
