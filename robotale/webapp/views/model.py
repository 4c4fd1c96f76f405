"""The Model page: the BPMN collaboration drawn with bpmn-js, coloured by what the log shows."""

from __future__ import annotations

from flask import (
    Blueprint,
    Response,
    current_app,
    jsonify,
    redirect,
    render_template,
    request,
    url_for,
)

from robotale.errors import InputError
from robotale.webapp import pages
from robotale.webapp.logdata import Cache
from robotale.webapp.model_store import ModelStore
from robotale.webapp.neo4j_access import driver

blueprint = Blueprint("model", __name__)


def store() -> ModelStore:
    return ModelStore(current_app.config["ROBOTALE"].model_dir)


@blueprint.get("/model")
def page():
    context = pages.context("model.page")
    models = store().all()
    chosen = request.args.get("model") or ""
    if not chosen and context["log"]:
        found = store().linked(context["log"]) or store().matching(log_robots(context["log"]))
        chosen = found.id if found else ""
    if not chosen and models:
        chosen = models[0].id
    return render_template("model.html", models=models, model=chosen, **context)


def log_robots(log: str) -> list[str]:
    from robotale.ekg.connection import database
    from robotale.ekg.queries import cypher

    records, _, _ = driver().execute_query(
        cypher("webapp_log_robots"), log=log, database_=database()
    )
    return [str(robot) for robot in records[0]["robots"]]


@blueprint.post("/model")
def upload():
    file = request.files.get("model")
    if file is None or not file.filename:
        raise InputError("Choose a .bpmn file to upload.")
    model = store().add(file.read(), file.filename)
    log = request.form.get("log", "")
    if log:
        store().link(log, model.id)
    return redirect(url_for("model.page", log=log or None, model=model.id))


@blueprint.get("/api/models/<model_id>.bpmn")
def xml(model_id: str):
    model = store().get(model_id)
    return Response(model.path.read_bytes(), mimetype="application/xml")


@blueprint.get("/api/models/<model_id>/frequencies")
def frequencies(model_id: str):
    """How often the chosen log shows each element of the model."""
    from robotale.webapp import overlay

    return jsonify(elements=_cached("frequencies", model_id, overlay.frequencies))


@blueprint.get("/api/models/<model_id>/deviations")
def deviations(model_id: str):
    """Where the chosen log deviates from the model (alignments: may take a while)."""
    from robotale.webapp import overlay

    return jsonify(_cached("deviations", model_id, overlay.deviations))


def _cached(kind: str, model_id: str, compute):
    from robotale.webapp.logdata import log_frame, log_info

    model = store().get(model_id)
    name = request.args.get("log", "")
    version = str(log_info(driver(), name).get("created"))
    return _results.get(
        (name, version, kind, model_id), lambda: compute(log_frame(driver(), name), model.path)
    )


#: conformance results are not small: the last two (frequencies and deviations) are enough
_results = Cache(2)
