"""The Model page: the BPMN collaboration drawn with bpmn-js, coloured by what the log shows."""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path
from typing import Any

import pandas as pd
from flask import Blueprint, Response, jsonify, redirect, render_template, request, url_for

from robotale.discovery.model_diff import diff_models
from robotale.ekg.logs import log_robots
from robotale.errors import InputError, ModelError
from robotale.fame_runtime.library import Library
from robotale.fame_runtime.parser import parse
from robotale.fame_runtime.splitter import split
from robotale.fame_runtime.verify import verify
from robotale.results.logdata import log_info
from robotale.webapp import overlay, pages
from robotale.webapp.model_store import ModelStore, StoredModel
from robotale.webapp.state import driver, state

blueprint = Blueprint("model", __name__)

#: how long the Model page's verification may explore before it reports what it found
VERIFY_SECONDS = 20.0


@blueprint.get("/model")
def page():
    context = pages.context("model.page")
    store = state().models
    log = context["log"]
    robots = sorted(log_robots(driver(), log)) if log else []
    models = _offered(store, log, robots) if log else store.all()
    chosen = request.args.get("model") or (models[0].id if models else "")
    return render_template(
        "model.html",
        models=models,
        others=store.all(),
        model=chosen,
        robots=robots,
        none_binds=bool(log) and not models,
        **context,
    )


def _offered(store: ModelStore, log: str, robots: list[str]) -> list[StoredModel]:
    """The model linked to ``log`` first, then every stored model whose pools bind all of the
    log's robots (none when the log names no robot)."""
    linked = store.linked(log)
    offered = [linked] if linked else []
    if robots:
        others = [m for m in store.all() if m.id != getattr(linked, "id", None)]
        offered += [m for m in others if _binds(m, robots)]
    return offered


def _binds(model: StoredModel, robots: list[str]) -> bool:
    """Whether the splitter binds every one of ``robots`` to a pool of ``model``."""
    try:
        split(parse(model.path), robots)
    except ModelError:
        return False
    return True


@blueprint.post("/model")
def upload():
    file = request.files.get("model")
    if file is None or not file.filename:
        raise InputError("Choose a .bpmn file to upload.")
    store = state().models
    model = store.add(file.read(), file.filename)
    log = request.form.get("log", "")
    if log:
        store.link(log, model.id)
    return redirect(url_for("model.page", log=log or None, model=model.id))


@blueprint.get("/api/models/<model_id>.bpmn")
def xml(model_id: str):
    model = state().models.get(model_id)
    # Plain text, a download and a sandbox: opened in a tab, the file cannot run anything on
    # the dashboard's origin (bpmn-js fetches it as text).
    response = Response(model.path.read_bytes(), mimetype="text/plain")
    response.headers["Content-Disposition"] = f'attachment; filename="{model_id}.bpmn"'
    response.headers["Content-Security-Policy"] = "default-src 'none'; sandbox"
    return response


@blueprint.get("/api/models/<model_id>/verify")
def verification(model_id: str):
    """What ``robotale fame verify`` finds in the model, each finding with its trace and the
    elements to highlight. Call activities are resolved among the stored models; one calling
    nothing stored runs like a skill. The model is verified as uploaded, scripts included
    (the page draws it without them)."""
    current = state()
    model = current.models.get(model_id)
    return jsonify(
        current.overlays.get(
            ("", "", "verify", model_id),
            lambda: verify(
                parse(model.original),
                library=Library(model.original.parent),
                opaque_calls=True,
                timeout=VERIFY_SECONDS,
            ).as_dict(),
        )
    )


@blueprint.get("/api/models/<model_id>/diff")
def difference(model_id: str):
    """The model as the driving one against the stored model ``against`` (one discovered from
    the runs): what the robots never used, what they did beyond it, signals never caught."""
    current = state()
    driving, discovered = (
        current.models.get(model_id),
        current.models.get(request.args.get("against", "")),
    )
    return jsonify(diff_models(driving.path, discovered.path).to_dict())


@blueprint.get("/api/models/<model_id>/frequencies")
def frequencies(model_id: str):
    """How often the chosen log shows each element of the model."""
    return jsonify(elements=_cached("frequencies", model_id, overlay.frequencies))


@blueprint.get("/api/models/<model_id>/deviations")
def deviations(model_id: str):
    """Where the chosen log deviates from the model (alignments: may take a while)."""
    return jsonify(_cached("deviations", model_id, overlay.deviations))


def _cached(kind: str, model_id: str, compute: Callable[[pd.DataFrame, Path], Any]) -> Any:
    current = state()
    model = current.models.get(model_id)
    name = request.args.get("log", "")
    version = str(log_info(driver(), name).get("created"))
    return current.overlays.get(
        (name, version, kind, model_id),
        lambda: compute(current.logs.frame(driver(), name), model.path),
    )
