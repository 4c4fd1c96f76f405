"""What every page's template needs: the menu, the stored logs and the chosen log, and static
files under URLs that change with their content (so browsers keep them without asking again).

Rendering a page lists the stored logs first, so a Neo4j that is down shows the error page that
says how to start it instead of a page whose data will never come; the list travels inside the
page, so its scripts need not ask for it before they ask for their data.
"""

from __future__ import annotations

import hashlib
from functools import cache
from typing import Any

from flask import Flask, request, url_for

from robotale.ekg.logs import list_logs
from robotale.webapp.state import driver

#: how long browsers keep a static file; its URL changes when its content does
STATIC_MAX_AGE = 365 * 24 * 3600


def context(endpoint: str) -> dict[str, Any]:
    return {"active": endpoint, "log": request.args.get("log", ""), "logs": list_logs(driver())}


def init_app(app: Flask) -> None:
    app.config["SEND_FILE_MAX_AGE_DEFAULT"] = STATIC_MAX_AGE
    static = app.static_folder

    @cache
    def version(filename: str) -> str:
        with open(f"{static}/{filename}", "rb") as stream:
            return hashlib.sha256(stream.read()).hexdigest()[:12]

    def asset(filename: str) -> str:
        return url_for("static", filename=filename, v=version(filename))

    app.jinja_env.globals["asset"] = asset
