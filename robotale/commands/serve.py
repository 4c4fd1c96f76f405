"""``robotale serve``: the dashboard in the foreground until Ctrl-C."""

from __future__ import annotations

from pathlib import Path

from robotale.results.replay import open_replay
from robotale.webapp.serve import serve


def serve_command(
    *,
    host: str | None = None,
    port: int | None = None,
    log: str | None = None,
    bag: Path | None = None,
) -> int:
    """Serve the dashboard on ``host``:``port`` (the dashboard's defaults when not given);
    with ``log``, print the address of that stored log's Discover page; with ``bag``, replay
    that recording without storing it and print the address of its Mission page."""
    replay = open_replay(bag) if bag is not None else None  # bad input before binding a port
    given = {"host": host, "port": port}
    serve(
        log=log,
        replay=replay,
        **{key: value for key, value in given.items() if value is not None},
    )
    return 0
