"""The application factory: ``create_app()`` builds the dashboard, one blueprint per page."""

from __future__ import annotations

import dataclasses
import threading
from typing import Any

from flask import Flask, redirect, url_for
from flask_wtf.csrf import CSRFProtect

from robotale import __version__
from robotale.webapp import defences, errors, pages, state, uploads
from robotale.webapp.page_registry import PAGES, menu
from robotale.webapp.settings import WebSettings


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
    threading.Thread(target=_warm_figures, daemon=True).start()
    app.jinja_env.globals.update(robotale_version=__version__, blueprints=app.blueprints)
    app.jinja_env.globals["menu"] = menu()

    @app.get("/")
    def index():
        return redirect(url_for("logs.page"))

    return app


def _warm_figures() -> None:
    """Import plotly.express and read plotly's default template while the dashboard waits
    for its first visitor: the first figure a page computes would otherwise wait for both
    (0.6 s and more)."""
    # function-level: 0.6 s to import, paid here in the background, not by the first figure
    import plotly.express  # noqa: F401
    import plotly.io as pio

    pio.templates[pio.templates.default]


def _register_blueprints(app: Flask) -> None:
    for page in PAGES:
        app.register_blueprint(page.view.blueprint)
