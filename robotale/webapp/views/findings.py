"""The Findings page, the first after a log is stored: the answers to an analyst's five
questions with links to their evidence (the graph node on the Perspectives page, the runs, a
run's timeline)."""

from __future__ import annotations

from flask import Blueprint, Response, render_template, request

from robotale.results.findings import parse_delay, stored_findings
from robotale.webapp import pages
from robotale.webapp.state import driver, state

blueprint = Blueprint("findings", __name__)


@blueprint.get("/findings")
def page():
    delay = request.args.get("delay", "")
    return render_template("findings.html", delay=delay, **pages.context("findings.page"))


@blueprint.get("/api/findings")
def findings():
    name = request.args.get("log", "")
    delay = parse_delay(request.args.get("delay"))
    data = stored_findings(driver(), state().logs, name, delay)
    return Response(data, mimetype="application/json")
