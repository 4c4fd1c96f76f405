"""The Cypher page: a read-only console with the queries of ``cypher/`` as examples."""

from __future__ import annotations

import dataclasses

from flask import Blueprint, jsonify, render_template, request

from robotale.errors import InputError
from robotale.webapp import console, pages
from robotale.webapp.state import driver, state

blueprint = Blueprint("console", __name__)


@blueprint.get("/cypher")
def page():
    examples = console.examples()
    return render_template(
        "cypher.html",
        examples=examples,
        examples_json=[dataclasses.asdict(example) for example in examples],
        **pages.context("console.page"),
    )


@blueprint.post("/api/cypher")
def run():
    body = request.get_json(silent=True)
    if not isinstance(body, dict) or not isinstance(body.get("query"), str):
        raise InputError('Send {"query": "...", "parameters": {...}} as JSON.')
    parameters = body.get("parameters") or {}
    if not isinstance(parameters, dict):
        raise InputError('The parameters must be a JSON object, e.g. {"log": "agri"}.')
    settings = state().settings
    results = console.run_read_only(
        driver(),
        body["query"],
        parameters,
        row_limit=settings.console_row_limit,
        timeout=settings.console_timeout,
    )
    return jsonify(results=[result.to_dict() for result in results])
