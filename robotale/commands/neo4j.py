"""``robotale neo4j start|stop|status``: the local Neo4j server."""

from __future__ import annotations

import dataclasses
import os

from robotale.ekg.connection import bolt_answers, settings
from robotale.ekg.jars import NEO4J_VERSION
from robotale.ekg.server import LocalServer, ServerOptions


def neo4j_start(
    *,
    bolt_port: int | None = None,
    http_port: int | None = None,
    heap: str | None = None,
    pagecache: str | None = None,
    timeout: float = 180.0,
) -> int:
    """Start the local server (options not given come from the environment's defaults)."""
    if os.environ.get("NEO4J_URI"):
        print(f"NEO4J_URI is set: robotale uses {os.environ['NEO4J_URI']}; nothing to start.")
        return 0
    given = {"bolt_port": bolt_port, "http_port": http_port, "heap": heap, "pagecache": pagecache}
    overrides = {field: value for field, value in given.items() if value is not None}
    options = dataclasses.replace(ServerOptions.from_env(), **overrides)
    server = LocalServer()
    already = server.running()
    state = server.start(options, timeout=timeout)
    verb = "was already running" if already else "is running"
    print(f"Neo4j {NEO4J_VERSION} {verb} at {state.bolt_uri} (pid {state.pid}).")
    print(f"Neo4j Browser: {state.browser_url}  user neo4j, password in {server.password_file}")
    return 0


def neo4j_stop() -> int:
    server = LocalServer()
    stopped = server.stop()
    if stopped is None:
        print(f"No local Neo4j was running (home {server.home}).")
    else:
        print(f"Stopped the local Neo4j (pid {stopped.pid}).")
    return 0


def neo4j_status() -> int:
    """Exit status 0 when the server answers, 3 when it does not (as init scripts do)."""
    where = settings()
    answers = bolt_answers(where.uri, where.auth)
    if where.from_env:
        origin = "NEO4J_URI"
    else:
        running = LocalServer().running()
        origin = f"local, pid {running.pid}" if running else "local, not running"
    print(f"Neo4j at {where.uri} ({origin}): {'answers' if answers else 'does not answer'}.")
    return 0 if answers else 3
