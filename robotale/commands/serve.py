"""``robotale serve``: the dashboard in the foreground until Ctrl-C."""

from __future__ import annotations

from robotale.webapp.serve import serve


def serve_command(
    *, host: str | None = None, port: int | None = None, log: str | None = None
) -> int:
    """Serve the dashboard on ``host``:``port`` (the dashboard's defaults when not given);
    with ``log``, print the address of that stored log's Discover page."""
    given = {"host": host, "port": port}
    serve(log=log, **{key: value for key, value in given.items() if value is not None})
    return 0
