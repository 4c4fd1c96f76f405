"""The Discover page's aggregation form: run an aggregation specification on the chosen log,
undo its last step, and draw any level (the aggregates after steps 1 .. k and the lifted
edges between them) as the page draws its other graphs."""

from __future__ import annotations

from typing import Any

import yaml
from flask import Blueprint, jsonify, request

from robotale.ekg.logs import require_log
from robotale.ekg.spec import parse_spec
from robotale.ekg.steps import level_graph, list_steps, run_spec, undo
from robotale.errors import InputError
from robotale.webapp.state import driver

blueprint = Blueprint("aggregation", __name__)

#: a specification is a few steps; more text than this is no specification
SPEC_LIMIT = 64 * 1024


@blueprint.get("/api/aggregation/steps")
def steps():
    name = request.args.get("log", "")
    require_log(driver(), name, "the Logs page lists those stored")
    return jsonify(steps=list_steps(driver(), name))


@blueprint.post("/api/aggregation/run")
def run():
    """Run the YAML specification ``spec`` on the log ``log`` (a JSON body)."""
    body = _body()
    text = body.get("spec")
    if not isinstance(text, str) or not text.strip() or len(text) > SPEC_LIMIT:
        raise InputError(
            f"Give the specification as YAML text of at most {SPEC_LIMIT:,} characters."
        )
    try:
        document = yaml.safe_load(text)
    except yaml.YAMLError as error:
        mark = getattr(error, "problem_mark", None)
        at = f" at line {mark.line + 1}" if mark is not None else ""
        raise InputError(f"The specification is not valid YAML{at}.") from None
    results = run_spec(driver(), _log(body), parse_spec(document))
    return jsonify(results=[result.to_dict() for result in results])


@blueprint.post("/api/aggregation/undo")
def undo_last():
    """Undo the last step of the log ``log`` (a JSON body)."""
    return jsonify(undone=undo(driver(), _log(_body())))


@blueprint.get("/api/aggregation/graph")
def graph():
    """Level ``level`` of the log's aggregation as the page's graph drawing takes it."""
    name = request.args.get("log", "")
    require_log(driver(), name, "the Logs page lists those stored")
    try:
        level = int(request.args.get("level", ""))
    except ValueError:
        raise InputError("Give the level as a step number (1, 2 ...).") from None
    return jsonify(drawable(level_graph(driver(), name, level), level))


def drawable(level: dict[str, list[dict[str, Any]]], number: int) -> dict[str, Any]:
    """The aggregates as nodes (labelled by their name), the lifted edges as edges; CORR
    edges are drawn like the flow of an entity type, named ``CORR``."""
    nodes = [
        {
            "id": a["id"],
            "label": a["name"] if a.get("origin") == "Event" else f"{a['type']}: {a['name']}",
            "kind": "entity" if a.get("origin") == "Entity" else "activity",
            "count": a["count"],
            "properties": {k: str(v) for k, v in a.items() if k not in ("log", "id", "name")},
        }
        for a in level["aggregates"]
    ]
    edges = [
        {
            "source": e["source"],
            "target": e["target"],
            "count": e["count"],
            "entity_type": e["entityType"] or e["type"],
        }
        for e in level["edges"]
    ]
    return {"kind": "aggregates", "level": number, "nodes": nodes, "edges": edges}


def _body() -> dict[str, Any]:
    body = request.get_json(silent=True)
    if not isinstance(body, dict):
        raise InputError("Send a JSON object with the log and, to run steps, the spec.")
    return body


def _log(body: dict[str, Any]) -> str:
    name = body.get("log")
    if not isinstance(name, str):
        raise InputError("Name the log to aggregate.")
    require_log(driver(), name, "the Logs page lists those stored")
    return name
