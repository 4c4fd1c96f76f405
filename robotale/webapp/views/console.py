"""The Cypher page: a read-only console with the queries of ``cypher/`` as examples."""

from __future__ import annotations

import dataclasses

from flask import Blueprint, jsonify, render_template, request

from robotale.errors import InputError, RobotaleError
from robotale.webapp import console, pages
from robotale.webapp.json_body import read_json
from robotale.webapp.state import state

blueprint = Blueprint("console", __name__)
#: what the console's endpoint takes
_SHAPE = '{"query": "...", "parameters": {...}}'


@blueprint.get("/cypher")
def page():
    examples = console.examples()
    return render_template(
        "cypher.html",
        examples=examples,
        examples_json=[dataclasses.asdict(example) for example in examples],
        notice=_notice(),
        **pages.context("console.page"),
    )


def _notice() -> str:
    # The page shows without Neo4j; the console's user is then a question for later.
    try:
        return console.login().notice
    except RobotaleError:
        return ""


@blueprint.post("/api/cypher")
def run():
    body = read_json(request, _SHAPE)
    if not isinstance(body, dict) or not isinstance(body.get("query"), str):
        raise InputError(f"Send {_SHAPE} as JSON.")
    parameters = body.get("parameters") or {}
    if not isinstance(parameters, dict):
        raise InputError('The parameters must be a JSON object, e.g. {"log": "agri"}.')
    app = state()
    results = console.run(body["query"], parameters, app.settings, app.console, app.neo4j.driver)
    return jsonify(results=results)
