"""What every request and every response of the dashboard goes through.

- A request whose ``Host`` names a host the dashboard does not serve is refused (403): a web
  page elsewhere cannot reach the dashboard through a name of its own that resolves to this
  machine (DNS rebinding). The names are :attr:`WebSettings.allowed_hosts`.
- Every response forbids scripts that are not the dashboard's own files (no inline script, no
  ``eval``, nothing from elsewhere), framing, MIME sniffing and sending the address on.
- The session cookie (the CSRF token's) is ``SameSite=Strict`` and ``HttpOnly``.
"""

from __future__ import annotations

from flask import Flask, Response, request

from robotale.webapp.settings import WebSettings

#: scripts only from the dashboard's files; styles may be set by the drawing libraries
#: (bpmn-js, plotly write style attributes), which cannot run code
CONTENT_SECURITY_POLICY = "; ".join(
    (
        "default-src 'self'",
        "script-src 'self'",
        "style-src 'self' 'unsafe-inline'",
        "img-src 'self' data: blob:",
        "font-src 'self' data:",
        "connect-src 'self'",
        "object-src 'none'",
        "base-uri 'none'",
        "form-action 'self'",
        "frame-ancestors 'none'",
    )
)
HEADERS = {
    "Content-Security-Policy": CONTENT_SECURITY_POLICY,
    "X-Frame-Options": "DENY",
    "X-Content-Type-Options": "nosniff",
    "Referrer-Policy": "no-referrer",
    "Cross-Origin-Opener-Policy": "same-origin",
}


def init_app(app: Flask, settings: WebSettings) -> None:
    app.config.update(SESSION_COOKIE_SAMESITE="Strict", SESSION_COOKIE_HTTPONLY=True)
    allowed = frozenset(settings.allowed_hosts)

    @app.before_request
    def _check_host():
        if "*" in allowed:
            return None
        name = host_name(request.host)
        if name in allowed:
            return None
        # A plain answer: the page of a foreign name gets nothing of the dashboard's.
        return Response(
            f"This dashboard does not answer to the host {name!r}; add it to "
            "ROBOTALE_ALLOWED_HOSTS if that is how it is reached.\n",
            status=403,
            mimetype="text/plain",
        )

    @app.after_request
    def _headers(response: Response) -> Response:
        for header, value in HEADERS.items():
            response.headers.setdefault(header, value)
        return response


def host_name(host: str) -> str:
    """The name of a ``Host`` header, without port, brackets or a trailing dot, lower case."""
    host = host.strip().lower()
    if host.startswith("["):
        return host[1:].split("]", 1)[0]
    if host.count(":") == 1:
        host = host.split(":", 1)[0]
    return host.rstrip(".")
