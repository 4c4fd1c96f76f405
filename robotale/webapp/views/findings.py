"""The Findings page, the first after a log is stored: the answers to an analyst's five
questions with links to their evidence (the graph node on the Perspectives page, the runs, a
run's timeline)."""

from __future__ import annotations

from typing import Any

from flask import Blueprint, jsonify, render_template, request

from robotale.discovery.graph import json_ready
from robotale.enhancement.findings import find
from robotale.webapp import pages
from robotale.webapp.logdata import log_info
from robotale.webapp.state import driver, state

blueprint = Blueprint("findings", __name__)


@blueprint.get("/findings")
def page():
    return render_template("findings.html", **pages.context("findings.page"))


@blueprint.get("/api/findings")
def findings():
    return jsonify(stored_findings(request.args.get("log", "")))


def stored_findings(name: str) -> dict[str, Any]:
    """The findings of the stored log ``name`` and its runs, computed once per version of the
    log."""
    current = state()
    version = str(log_info(driver(), name).get("created"))

    def compute() -> dict[str, Any]:
        result = find(current.logs.frame(driver(), name))
        runs = result.runs.reindex(columns=["case", "start", "duration"])
        return json_ready({**result.to_dict(), "runs": runs.to_dict(orient="records")})

    return current.findings.get((name, version, "findings"), compute)
