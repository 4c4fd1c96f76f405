"""What the user sees when something goes wrong: one sentence, and what to do about it.

Pages get an HTML error page, the JSON endpoints under ``/api/`` an ``{"error": ...}`` object
with the same sentence. Neo4j being down is the common case and says how to start it.
"""

from __future__ import annotations

from flask import Flask, jsonify, render_template, request
from flask_wtf.csrf import CSRFError
from neo4j.exceptions import ServiceUnavailable, SessionExpired
from werkzeug.exceptions import HTTPException, RequestEntityTooLarge

from robotale.ekg.connection import settings, unreachable_message
from robotale.errors import InputError, RobotaleError, ServerError


def wants_json() -> bool:
    return request.path.startswith("/api/")


def error_response(message: str, status: int, title: str, hint: str = ""):
    if wants_json():
        return jsonify(error=message, hint=hint), status
    page = render_template("error.html", title=title, message=message, hint=hint)
    return page, status


def _server_down(error: Exception):
    message = str(error) if isinstance(error, ServerError) else unreachable_message(settings())
    hint = (
        "Start the local server with `robotale neo4j start` (or set NEO4J_URI, NEO4J_USER and "
        "NEO4J_PASSWORD to a running one), then reload this page."
    )
    return error_response(message, 503, "Neo4j is not available", hint)


def init_app(app: Flask) -> None:
    app.register_error_handler(ServerError, _server_down)
    app.register_error_handler(ServiceUnavailable, _server_down)
    app.register_error_handler(SessionExpired, _server_down)

    @app.errorhandler(InputError)
    def _bad_input(error: InputError):
        return error_response(str(error), 400, "That did not work")

    @app.errorhandler(RobotaleError)
    def _other(error: RobotaleError):
        return error_response(str(error), 400, "That did not work")

    @app.errorhandler(CSRFError)
    def _csrf(error: CSRFError):
        return error_response(
            f"The form could not be accepted ({error.description.rstrip('.')}).",
            400,
            "Please send the form again",
            "Reload the page and send the form again.",
        )

    @app.errorhandler(RequestEntityTooLarge)
    def _too_large(error: RequestEntityTooLarge):
        limit = app.config["MAX_CONTENT_LENGTH"] // (1024 * 1024)
        return error_response(
            f"The upload is larger than the limit of {limit} MB.",
            413,
            "The file is too large",
            "Raise the limit with ROBOTALE_UPLOAD_LIMIT_MB when starting `robotale serve`.",
        )

    @app.errorhandler(HTTPException)
    def _http(error: HTTPException):
        return error_response(error.description or error.name, error.code or 500, error.name)
