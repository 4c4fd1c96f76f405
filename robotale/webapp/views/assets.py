"""plotly.js, served from the copy inside the plotly Python package (no CDN, no npm)."""

from __future__ import annotations

import hashlib
from functools import cache

from flask import Blueprint, Response, request
from plotly.offline import get_plotlyjs

blueprint = Blueprint("assets", __name__)


@cache
def _plotly() -> tuple[bytes, str]:
    script = get_plotlyjs().encode("utf-8")
    return script, hashlib.sha256(script).hexdigest()[:16]


@blueprint.get("/vendor/plotly.min.js")
def plotly_js():
    script, etag = _plotly()
    if request.if_none_match.contains(etag):
        return Response(status=304)
    response = Response(script, mimetype="text/javascript")
    response.set_etag(etag)
    response.cache_control.public = True
    response.cache_control.max_age = 86400
    return response
