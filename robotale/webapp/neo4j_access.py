"""The dashboard's one Neo4j driver, connected on first use.

The app starts whether or not Neo4j answers: a page that needs the database connects then, and
a server that is down becomes the error page of :mod:`robotale.webapp.errors` (the next request
tries again, so starting Neo4j is enough to recover).
"""

from __future__ import annotations

import threading

from flask import Flask, current_app
from neo4j import Driver

from robotale.ekg.connection import connect

_KEY = "robotale.neo4j"


class _Holder:
    def __init__(self) -> None:
        self.lock = threading.Lock()
        self.driver: Driver | None = None


def init_app(app: Flask) -> None:
    app.extensions[_KEY] = _Holder()


def driver() -> Driver:
    """The connected driver of the current app (a ``ServerError`` when Neo4j is down)."""
    holder: _Holder = current_app.extensions[_KEY]
    with holder.lock:
        if holder.driver is None:
            holder.driver = connect()
        return holder.driver


def close(app: Flask) -> None:
    holder: _Holder = app.extensions[_KEY]
    with holder.lock:
        if holder.driver is not None:
            holder.driver.close()
            holder.driver = None
