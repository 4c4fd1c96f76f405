"""The Perspectives page: the bottleneck ranking, then spatial, communication, battery and
performance (with the variants) for the whole log or, after a click on a node of its process
graph, for that activity or class (figure 7.8)."""

from __future__ import annotations

from collections.abc import Callable

from flask import Blueprint, abort, jsonify, render_template, request

from robotale import enhancement
from robotale.enhancement.findings import trusted_first
from robotale.enhancement.result import Perspective
from robotale.webapp import pages
from robotale.webapp.state import driver, state

blueprint = Blueprint("perspectives", __name__)

MAKERS: dict[str, Callable[..., Perspective]] = {
    "bottlenecks": enhancement.find_bottlenecks,
    "spatial": enhancement.spatial_perspective,
    "communication": enhancement.communication_perspective,
    "battery": enhancement.battery_perspective,
    "performance": enhancement.performance_perspective,
}
NAMES = tuple(MAKERS)


@blueprint.get("/perspectives")
def page():
    return render_template(
        "perspectives.html",
        names=NAMES,
        activity=request.args.get("activity", ""),
        robot=request.args.get("robot", ""),
        **pages.context("perspectives.page"),
    )


@blueprint.get("/api/perspectives/<name>")
def perspective(name: str):
    if name not in MAKERS:
        abort(404, f"There is no {name!r} perspective; there are {', '.join(NAMES)}.")
    result = MAKERS[name](
        state().logs.frame(driver(), request.args.get("log", "")),
        activity=request.args.get("activity") or None,
        robot=request.args.get("robot") or None,
    )
    if name == "bottlenecks" and result.has_data:
        # the same order as the Findings page: effects that may be chance come last
        result.tables["bottlenecks"] = trusted_first(result.tables["bottlenecks"])
    return jsonify(result.to_dict())
