"""How far the preparation of a log's pages is: the Findings, Perspectives and Timeline pages
ask before they ask for anything else. A log whose pages nobody prepared (stored with
``--pages visit``, or its preparation died) gets its preparation started by the first such
question, in the dashboard; the page shows "preparing … N of M" until the results it shows
are ready, then shows them. Its later questions wait (``?wait=``) until the preparation goes
on, so the page hears of its results as soon as they are kept."""

from __future__ import annotations

from flask import Blueprint, jsonify, request

from robotale.results.findings import parse_seconds
from robotale.webapp.state import driver, state

blueprint = Blueprint("preparation", __name__)


@blueprint.get("/api/preparation")
def preparation():
    known = state()
    name, page = request.args.get("log", ""), request.args.get("page", "")
    # how long an answer that is not ready may wait (missing: not at all)
    wait = parse_seconds(request.args.get("wait"), "the wait") or 0.0
    found = known.preparations.status(driver(), known.logs, name, page, wait)
    return jsonify(found.to_dict())
