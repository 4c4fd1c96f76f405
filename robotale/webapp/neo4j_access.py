"""The dashboard's one Neo4j driver, connected on first use.

The app starts whether or not Neo4j answers: a page that needs the database connects then, and
a server that is down becomes the error page of :mod:`robotale.webapp.errors` (the next request
tries again, so starting Neo4j is enough to recover).
"""

from __future__ import annotations

import threading

from neo4j import Driver

from robotale.ekg.connection import connect


class Neo4jAccess:
    """One app's driver: connected by the first request that needs it, closed with the app."""

    def __init__(self) -> None:
        self._lock = threading.Lock()
        self._driver: Driver | None = None

    def driver(self) -> Driver:
        """The connected driver (a ``ServerError`` when Neo4j is down)."""
        with self._lock:
            if self._driver is None:
                self._driver = connect()
            return self._driver

    def close(self) -> None:
        with self._lock:
            if self._driver is not None:
                self._driver.close()
                self._driver = None
