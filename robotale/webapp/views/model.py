"""The Model page: the BPMN collaboration drawn with bpmn-js, coloured by what the log shows."""

from __future__ import annotations

from flask import Blueprint, Response, current_app, redirect, render_template, request, url_for

from robotale.errors import InputError
from robotale.webapp import pages
from robotale.webapp.models import ModelStore

blueprint = Blueprint("model", __name__)


def store() -> ModelStore:
    return ModelStore(current_app.config["ROBOTALE"].model_dir)


@blueprint.get("/model")
def page():
    context = pages.context("model.page")
    models = store().all()
    chosen = request.args.get("model") or ""
    if not chosen and context["log"]:
        linked = store().linked(context["log"])
        chosen = linked.id if linked else ""
    if not chosen and models:
        chosen = models[0].id
    return render_template("model.html", models=models, model=chosen, **context)


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
