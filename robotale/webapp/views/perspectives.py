"""The Perspectives page: spatial, communication, battery and performance figures for the whole
log or, after a click on a node of its process graph, for that activity or class (figure 7.8)."""

from __future__ import annotations

from flask import Blueprint, abort, jsonify, render_template, request

from robotale import enhancement
from robotale.webapp import pages
from robotale.webapp.state import driver, state

blueprint = Blueprint("perspectives", __name__)

NAMES = ("spatial", "communication", "battery", "performance")


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
    if name not in NAMES:
        abort(404, f"There is no {name!r} perspective; there are {', '.join(NAMES)}.")
    make = getattr(enhancement, f"{name}_perspective")
    result = make(
        state().logs.frame(driver(), request.args.get("log", "")),
        activity=request.args.get("activity") or None,
        robot=request.args.get("robot") or None,
    )
    return jsonify(result.to_dict())
