"""Serve the dashboard: :func:`serve` in the foreground (``robotale serve``, ``robotale
demo``), or a :class:`Dashboard` in a background thread (tests, benchmarks)."""

from __future__ import annotations

import errno
import ipaddress
import socket
import sys
import threading
from urllib.parse import urlencode

from flask import Flask
from werkzeug.serving import BaseWSGIServer, make_server

from robotale.errors import ServerError
from robotale.results.replay import Replay
from robotale.webapp import console
from robotale.webapp.app import create_app
from robotale.webapp.settings import DEFAULT_HOST, DEFAULT_PORT
from robotale.webapp.state import state


class Dashboard:
    """A running dashboard: ``url``, and ``stop()`` when done (or use it as a context)."""

    def __init__(
        self, app: Flask | None = None, host: str = DEFAULT_HOST, port: int = DEFAULT_PORT
    ):
        self.app = app if app is not None else create_app()
        self.server = _bind(self.app, host, port)
        self._thread: threading.Thread | None = None

    @property
    def url(self) -> str:
        host = self.server.host
        shown = f"[{host}]" if ":" in host else host
        return f"http://{shown}:{self.server.port}"

    def start(self) -> Dashboard:
        self._thread = threading.Thread(target=self.server.serve_forever, daemon=True)
        self._thread.start()
        return self

    def stop(self) -> None:
        self.server.shutdown()
        self.server.server_close()
        if self._thread is not None:
            self._thread.join(timeout=10)
        state(self.app).neo4j.close()
        state(self.app).console.close()

    def __enter__(self) -> Dashboard:
        return self.start()

    def __exit__(self, *exc: object) -> None:
        self.stop()


def _bind(app: Flask, host: str, port: int) -> BaseWSGIServer:
    # The socket is ours, so a port in use is our one sentence rather than werkzeug's exit.
    family = socket.AF_INET6 if ":" in host else socket.AF_INET
    try:
        listening = socket.create_server((host, port), family=family)
    except OSError as error:
        if error.errno == errno.EADDRINUSE:
            raise ServerError(
                f"Port {port} on {host} is in use: choose another with --port."
            ) from None
        raise ServerError(f"Cannot serve the dashboard on {host}:{port} ({error}).") from None
    with listening:
        return make_server(host, port, app, threaded=True, fd=listening.fileno())


def serve(
    host: str = DEFAULT_HOST,
    port: int = DEFAULT_PORT,
    log: str | None = None,
    replay: Replay | None = None,
) -> None:
    """Serve the dashboard until Ctrl-C; with ``log``, point at that log's Discover page; with
    ``replay``, serve it and point at its first run's Mission page."""
    dashboard = Dashboard(host=host, port=port)
    where = None
    if replay is not None:
        add_replay(dashboard.app, replay)
        where = mission_path(replay)
    elif log:
        where = discover_path(log)
    serve_until_interrupted(dashboard, where)


def add_replay(app: Flask, replay: Replay) -> None:
    """Serve ``replay`` on the Mission page of ``app`` under its name."""
    state(app).replays[replay.name] = replay


def discover_path(log: str) -> str:
    """The Discover page of the stored log ``log``."""
    return f"/discover?{urlencode({'log': log})}"


def mission_path(replay: Replay) -> str:
    """The Mission page of the replay's first run."""
    return f"/mission?{urlencode({'log': replay.name, 'case': replay.cases[0]})}"


def serve_until_interrupted(dashboard: Dashboard, path: str | None = None) -> None:
    """Serve a dashboard bound earlier in this thread until Ctrl-C (which werkzeug turns into
    a normal return); ``path``: the page to print the address of."""
    url = dashboard.url
    where = f"{url}{path}" if path else url
    print(f"robotale dashboard at {where}  (Ctrl-C stops it)", file=sys.stderr, flush=True)
    if not _is_loopback(dashboard.server.host):
        print(
            f"Listening on {dashboard.server.host}: anyone who can reach this machine can read "
            "the logs. It answers to localhost and 127.0.0.1; add the names it is reached by "
            "to ROBOTALE_ALLOWED_HOSTS.",
            file=sys.stderr,
        )
    if notice := console.own_user_notice():
        print(notice, file=sys.stderr)
    try:
        dashboard.server.serve_forever()
    finally:
        dashboard.server.server_close()


def _is_loopback(host: str) -> bool:
    try:
        return ipaddress.ip_address(host).is_loopback
    except ValueError:
        return host == "localhost"
