"""Where a live run is followed: its Mission page's address, and whether a dashboard serving
it answers there (one that reads the Neo4j server the run is stored in)."""

from __future__ import annotations

import json
import urllib.request
from urllib.parse import quote, urlencode, urlsplit

from robotale.errors import InputError
from robotale.webapp.settings import DEFAULT_HOST, DEFAULT_PORT

#: where ``robotale serve`` answers unless told otherwise
DEFAULT_DASHBOARD = f"http://{DEFAULT_HOST}:{DEFAULT_PORT}"
#: seconds a dashboard has to answer before it is taken for absent
PATIENCE = 10.0


def dashboard_url(text: str | None) -> str:
    """``--dashboard URL`` (default :data:`DEFAULT_DASHBOARD`), without a trailing slash."""
    url = (text or DEFAULT_DASHBOARD).rstrip("/")
    parts = urlsplit(url)
    if parts.scheme not in ("http", "https") or not parts.netloc:
        raise InputError(f"--dashboard {text!r} is not a dashboard's address (http://HOST:PORT).")
    return url


def live_page(url: str, name: str) -> str:
    """The Mission page of the live run ``name`` on the dashboard at ``url``."""
    return f"{url}/mission?{urlencode({'log': name, 'case': name})}"


def serves_live(url: str, name: str) -> bool:
    """Whether the dashboard at ``url`` answers on the live run ``name`` as a live run."""
    segment = quote(name, safe="")
    try:
        with urllib.request.urlopen(
            f"{url}/api/mission/{segment}/{segment}", timeout=PATIENCE
        ) as answer:
            return json.load(answer).get("live") is True
    except (OSError, ValueError):  # nothing there, an error page, no JSON
        return False
