"""What every page's template needs: the page's name for the menu and the chosen log.

Rendering a page first checks that Neo4j answers, so a server that is down shows the error page
that says how to start it instead of a page whose data will never come.
"""

from __future__ import annotations

from typing import Any

from flask import request

from robotale.webapp.neo4j_access import driver


def context(endpoint: str) -> dict[str, Any]:
    driver().verify_connectivity()
    return {"active": endpoint, "log": request.args.get("log", "")}
