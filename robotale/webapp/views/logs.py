"""The Logs page: upload a log, choose its properties and entities, ingest it; list, delete."""

from __future__ import annotations

from flask import (
    Blueprint,
    abort,
    flash,
    jsonify,
    redirect,
    render_template,
    request,
    url_for,
)

from robotale.ekg.columnar import delete_copies
from robotale.ekg.logs import delete_log, list_logs, require_log
from robotale.errors import InputError
from robotale.eventlog.readers import parse_mapping
from robotale.webapp import ingest, pages, uploads
from robotale.webapp.jobs import Jobs
from robotale.webapp.settings import WebSettings
from robotale.webapp.state import driver, state

blueprint = Blueprint("logs", __name__)


def pending_logs() -> ingest.PendingLogs:
    return state().pending


def settings() -> WebSettings:
    return state().settings


def jobs() -> Jobs:
    return state().jobs


def stored_logs() -> list[dict]:
    return list_logs(driver())


@blueprint.get("/logs")
def page():
    context = pages.context("logs.page")
    return render_template("logs.html", **context)


@blueprint.get("/api/logs")
def api_logs():
    return jsonify(logs=stored_logs())


@blueprint.post("/logs/upload")
def upload():
    file = request.files.get("file")
    if file is None or not file.filename:
        raise InputError("Choose a CSV, XES or OCEL 2.0 log or a zipped bag folder to upload.")
    pairs = [pair for pair in request.form.get("mapping", "").split(",") if pair.strip()]
    mapping = parse_mapping(pairs)
    uploads.remove_stale(settings().upload_dir)
    saved = uploads.save(file.stream, file.filename, settings().upload_dir)
    case_gap = request.form.get("case_gap", "").strip() or None
    pending = pending_logs().add(saved, mapping, case_gap)
    return _read(pending)


@blueprint.post("/logs/upload/<token>/split")
def split(token: str):
    """Read the upload again as runs split at every pause of the given length: the offer the
    column page makes for a log of several days without a case column."""
    pending = pending_logs().get(token)
    case_gap = request.form.get("case_gap", "").strip()
    if not case_gap:
        raise InputError("Give the pause that ends a run, e.g. 1h or 30min.")
    pending.case_gap = case_gap
    return _read(pending)


def _read(pending: ingest.Pending):
    """Read the pending upload in a job; its column page shows when it is done."""
    limit = settings().upload_limit_mb * 1024 * 1024
    models = state().models
    job = jobs().submit(
        f"Reading {pending.upload.filename}",
        lambda job: ingest.read_upload(pending, limit, models, job) or {},
    )
    return redirect(url_for("logs.choose", token=pending.upload.token, job=job.id))


@blueprint.get("/logs/upload/<token>")
def choose(token: str):
    context = pages.context("logs.page")
    job = jobs().get(request.args.get("job", ""))
    if job is not None and not job.finished:
        return render_template("logs_job.html", job=job, then="reload", **context)
    if job is not None and job.error:
        return render_template("logs_job.html", job=job, then="", **context)
    pending = pending_logs().get(token)
    return render_template(
        "logs_columns.html",
        token=token,
        filename=pending.upload.filename,
        name=pending.upload.suggested_name,
        events=len(pending.log),
        reading=pending.reading,
        session_gap=pending.session_gap,
        columns=ingest.columns(pending.log, pending.objects),
        **context,
    )


@blueprint.post("/logs/upload/<token>")
def start_ingest(token: str):
    pending = pending_logs().get(token)
    name = request.form.get("name", "").strip()
    if not name:
        raise InputError("Give the log a name.")
    entities = request.form.getlist("entity")
    log = ingest.chosen_log(pending.log, request.form.getlist("store"), entities, pending.objects)
    pending.log = log
    pending_logs().pop(token)
    replace = request.form.get("replace") == "on"
    connected, models, logs = driver(), state().models, state().logs
    preparations = state().preparations

    def work(job):
        stored = ingest.ingest(connected, pending, name, entities, replace, models, logs, job)
        # the findings, perspectives and timeline, prepared while the user reads that the log
        # is stored (a page visited before they are ready shows how far they are)
        preparations.status(connected, logs, name)
        return stored

    job = jobs().submit(f"Storing {name}", work)
    return redirect(url_for("logs.job_page", job_id=job.id, log=name))


@blueprint.get("/logs/jobs/<job_id>")
def job_page(job_id: str):
    job = jobs().get(job_id) or abort(404, "That job is unknown (the dashboard was restarted?).")
    return render_template("logs_job.html", job=job, then="", **pages.context("logs.page"))


@blueprint.get("/api/jobs/<job_id>")
def job_state(job_id: str):
    job = jobs().get(job_id) or abort(404, "That job is unknown (the dashboard was restarted?).")
    return jsonify(job.to_dict())


@blueprint.post("/logs/delete")
def delete():
    name = request.form.get("name", "")
    require_log(driver(), name, "the Logs page lists those stored")
    delete_log(driver(), name)
    delete_copies(name)
    state().logs.forget(name)
    flash(f"Deleted the log {name!r}.", "success")
    return redirect(url_for("logs.page"))
