"""The application factory: ``create_app()`` builds the dashboard, one blueprint per page."""

from __future__ import annotations

import dataclasses
from typing import Any

from flask import Flask, redirect, url_for
from flask_wtf.csrf import CSRFProtect

from robotale import __version__
from robotale.webapp import defences, errors, pages, state, uploads
from robotale.webapp.settings import WebSettings
from robotale.webapp.views import (
    aggregation,
    assets,
    console,
    discover,
    findings,
    logs,
    mission,
    model,
    perspectives,
    timeline,
)


def create_app(settings: WebSettings | None = None, **overrides: Any) -> Flask:
    """The dashboard for the Neo4j robotale is configured to use (see ``robotale.ekg``).

    ``settings`` default to :meth:`WebSettings.from_env`; keyword ``overrides`` replace single
    fields (``create_app(upload_limit_mb=10)``).
    """
    settings = dataclasses.replace(settings or WebSettings.from_env(), **overrides)
    app = Flask(__name__)
    app.config.update(
        SECRET_KEY=settings.secret_key,
        MAX_CONTENT_LENGTH=settings.upload_limit_mb * 1024 * 1024,
        JSON_SORT_KEYS=False,
    )
    app.json.sort_keys = False
    defences.init_app(app, settings)
    CSRFProtect(app)
    uploads.remove_stale(settings.upload_dir)
    state.init_app(app, settings).models.add_shipped()
    errors.init_app(app)
    pages.init_app(app)
    _register_blueprints(app)
    app.jinja_env.globals.update(robotale_version=__version__, blueprints=app.blueprints)

    @app.get("/")
    def index():
        return redirect(url_for("logs.page"))

    return app


def _register_blueprints(app: Flask) -> None:
    for module in (
        assets,
        logs,
        findings,
        discover,
        aggregation,
        perspectives,
        timeline,
        mission,
        model,
        console,
    ):
        app.register_blueprint(module.blueprint)
