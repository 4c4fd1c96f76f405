"""The dashboard's app-level objects, made once by ``create_app`` and kept in
``app.extensions``: the settings, the Neo4j driver, the background jobs, the uploads waiting for
their column choice, the model store, the console's workers and the caches.

Nothing of the kind lives in a module: two apps in one process (the tests, a benchmark) each
have their own. Views reach the current app's through :func:`state`; work that runs outside a
request (a job's thread) is handed the objects it needs.
"""

from __future__ import annotations

from dataclasses import dataclass, field

from flask import Flask, current_app, g, request
from neo4j import Driver

from robotale.ekg.logs import end_look, start_look
from robotale.results.background import Preparations
from robotale.results.logdata import Cache, LogData
from robotale.results.replay import Replay
from robotale.webapp.console_pool import Pool
from robotale.webapp.ingest import PendingLogs
from robotale.webapp.jobs import Jobs
from robotale.webapp.model_store import ModelStore
from robotale.webapp.neo4j_access import Neo4jAccess
from robotale.webapp.settings import WebSettings

_KEY = "robotale"
#: conformance results are not small: the last two (frequencies and deviations) are enough
OVERLAYS_KEPT = 2


@dataclass
class AppState:
    settings: WebSettings
    models: ModelStore
    #: the Cypher console's capped worker processes
    console: Pool
    neo4j: Neo4jAccess = field(default_factory=Neo4jAccess)
    jobs: Jobs = field(default_factory=Jobs)
    pending: PendingLogs = field(default_factory=PendingLogs)
    #: stored logs' DataFrames, class graphs and the results the pages show
    logs: LogData = field(default_factory=LogData)
    #: the preparations of logs' pages this dashboard started (a page visited first)
    preparations: Preparations = field(default_factory=Preparations)
    #: recordings replayed without storing them (``robotale serve --bag``), by name
    replays: dict[str, Replay] = field(default_factory=dict)
    #: the Model page's frequencies and deviations
    overlays: Cache = field(default_factory=lambda: Cache(OVERLAYS_KEPT))


def init_app(app: Flask, settings: WebSettings) -> AppState:
    """Give ``app`` its objects."""
    workers = Pool(settings.console_workers, settings.console_memory_mb)
    app.extensions[_KEY] = made = AppState(settings, ModelStore(settings.model_dir), workers)

    @app.before_request
    def _look() -> None:
        # a page's answer reads a log's Log node for every result it touches: once is enough
        # for what only reads (GET); what changes logs reads it afresh
        if request.method == "GET":
            g.robotale_look = start_look()

    @app.teardown_request
    def _end_look(_error: BaseException | None) -> None:
        token = g.pop("robotale_look", None)
        if token is not None:
            end_look(token)

    return made


def state(app: Flask | None = None) -> AppState:
    """The objects of ``app``, by default of the app handling the current request."""
    return (app if app is not None else current_app).extensions[_KEY]


def driver() -> Driver:
    """The current app's connected Neo4j driver (a ``ServerError`` when Neo4j is down)."""
    return state().neo4j.driver()
