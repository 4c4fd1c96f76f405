"""The Perspectives page: the bottleneck ranking, then spatial, communication, battery and
performance (with the variants) for the whole log or, after a click on a node of its process
graph, for that activity or class (figure 7.8). Each section is its own request, so the page
shows each as soon as it is ready."""

from __future__ import annotations

from flask import Blueprint, Response, abort, render_template, request

from robotale.enhancement.registry import page_names
from robotale.results.findings import parse_delay, stored_perspective
from robotale.webapp import pages
from robotale.webapp.state import driver, state

blueprint = Blueprint("perspectives", __name__)

#: the page's sections, in the order the registry gives them
NAMES = page_names()


@blueprint.get("/perspectives")
def page():
    return render_template(
        "perspectives.html",
        names=NAMES,
        activity=request.args.get("activity", ""),
        robot=request.args.get("robot", ""),
        delay=request.args.get("delay", ""),
        **pages.context("perspectives.page"),
    )


@blueprint.get("/api/perspectives/<name>")
def perspective(name: str):
    if name not in NAMES:
        abort(404, f"There is no {name!r} perspective; there are {', '.join(NAMES)}.")
    data = stored_perspective(
        driver(),
        state().logs,
        request.args.get("log", ""),
        name,
        activity=request.args.get("activity") or None,
        robot=request.args.get("robot") or None,
        delay=parse_delay(request.args.get("delay")),
    )
    return Response(data, mimetype="application/json")
