"""``robotale neo4j start|stop|status``: the local Neo4j server."""

from __future__ import annotations

import dataclasses
import os
import sys
from pathlib import Path

from robotale.ekg.connection import bolt_answers, settings
from robotale.neo4j_server.jars import release
from robotale.neo4j_server.server import CRASHED, OTHER, RUNNING, LocalServer, ServerOptions
from robotale.neo4j_server.server_config import check_plugins


def neo4j_start(
    *,
    bolt_port: int | None = None,
    http_port: int | None = None,
    heap: str | None = None,
    pagecache: str | None = None,
    plugins: str | None = None,
    version: str | None = None,
    timeout: float = 180.0,
) -> int:
    """Start the local server (options not given come from the environment's defaults)."""
    if os.environ.get("NEO4J_URI"):
        print(f"NEO4J_URI is set: robotale uses {os.environ['NEO4J_URI']}; nothing to start.")
        return 0
    given = {
        "bolt_port": bolt_port,
        "http_port": http_port,
        "heap": heap,
        "pagecache": pagecache,
        "plugins": Path(plugins).expanduser() if plugins else None,
        "version": version,
    }
    overrides = {field: value for field, value in given.items() if value is not None}
    server = LocalServer()
    options = dataclasses.replace(server.recorded_options(), **overrides)
    already = server.running()
    if already is None and server.condition().condition == CRASHED:
        print("The local Neo4j had crashed; starting it again.")
    state = server.start(options, timeout=timeout, progress=_progress)
    verb = "was already running" if already else "is running"
    # a server that was already running runs the release its data was written by
    version = server.data_version() if already else None
    version = version or release(options.version).version
    print(f"Neo4j {version} {verb} at {state.bolt_uri} (pid {state.pid}).")
    print(f"Neo4j Browser: {state.browser_url}  user neo4j, password in {server.password_file}")
    if not already:
        _report_plugins(server, options)
    return 0


def _report_plugins(server: LocalServer, options: ServerOptions) -> None:
    folder = server.plugins_folder(options)
    if folder is not None:
        names = ", ".join(jar.name for jar in check_plugins(folder)) or "none"
        print(f"Plugins from {folder}: {names}")


def neo4j_stop() -> int:
    server = LocalServer()
    stopped = server.stop()
    if stopped is None:
        print(f"No local Neo4j was running (home {server.home}).")
    else:
        print(f"Stopped the local Neo4j (pid {stopped.pid}).")
    return 0


def neo4j_status() -> int:
    """Exit status as init scripts give it: 0 running and answering, 1 crashed (its pid is
    gone, it was not stopped), 3 stopped or not answering, 4 stopped while something else
    answers on its port (robotale will not use that)."""
    where = settings()
    if where.from_env:
        answers = bolt_answers(where.uri, where.auth)
        print(f"Neo4j at {where.uri} (NEO4J_URI): {'answers' if answers else 'does not answer'}.")
        return 0 if answers else 3
    state = LocalServer().condition()
    record = state.record
    if state.condition == RUNNING and record is not None:
        answers = bolt_answers(where.uri, where.auth)
        print(
            f"Neo4j at {where.uri} (local, pid {record.pid}): "
            f"{'answers' if answers else 'does not answer yet'}."
        )
        return 0 if answers else 3
    if state.condition == CRASHED and record is not None:
        print(
            f"Neo4j at {where.uri} (local, crashed): its process {record.pid} is gone but it "
            "was never stopped; start it again with `robotale neo4j start`."
        )
        return 1
    if state.condition == OTHER:
        print(
            f"Neo4j at {where.uri} (local, not running): something else answers on that port; "
            "robotale does not use it (set NEO4J_URI to use that server)."
        )
        return 4
    print(f"Neo4j at {where.uri} (local, not running): does not answer.")
    return 3


def _progress(line: str) -> None:
    print(line, file=sys.stderr, flush=True)
