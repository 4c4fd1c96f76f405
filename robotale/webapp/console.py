"""The Cypher console's work: run a user's query so that it can only read, and show the rows.

The checks and the running are :mod:`robotale.ekg.readonly`'s (text, plan, READ transaction,
bounded answer). Here the console picks its Neo4j user and runs each request on one of a few
long-lived worker processes whose memory is capped (``console_memory_mb``,
:mod:`robotale.webapp.console_pool`), so that no answer can grow the dashboard itself; a
query that outlives its time is the watchdog's (:mod:`robotale.webapp.console_watchdog`).
Values come in as parameters, never pasted into the text. The examples are the analyst's
questions among the files of ``cypher/`` (``ask_*``).

Its user: ``ROBOTALE_CONSOLE_USER`` and ``ROBOTALE_CONSOLE_PASSWORD`` when set; otherwise, on
robotale's local server, a user of its own that the server creates (``robotale_console``);
otherwise (``NEO4J_URI``) robotale's own user, and the page says how to give it a reader.
"""

from __future__ import annotations

import os
import queue
import re
import uuid
from collections.abc import Callable
from dataclasses import dataclass
from importlib.resources import files
from typing import Any

from neo4j import Driver

from robotale.ekg.connection import Settings, database, settings
from robotale.ekg.readonly import (
    QueryRefused,
    StatementResult,
    WriteRefused,
    cell,
    run_read_only,
)
from robotale.errors import InputError, RobotaleError, ServerError
from robotale.neo4j_server.server import LocalServer
from robotale.queries import split_statements
from robotale.webapp import console_watchdog
from robotale.webapp.console_pool import Died, NoAnswer, Pool
from robotale.webapp.settings import WebSettings

__all__ = [
    "QueryRefused",
    "StatementResult",
    "WriteRefused",
    "cell",
    "examples",
    "run",
    "run_read_only",
    "split_statements",
]

_PARAMETER = re.compile(r"\$([A-Za-z_][A-Za-z0-9_]*)")
_ERRORS: dict[str, type[RobotaleError]] = {
    error.__name__: error for error in (InputError, QueryRefused, WriteRefused, ServerError)
}


@dataclass(frozen=True)
class Example:
    name: str
    description: str
    text: str
    parameters: list[str]


@dataclass(frozen=True)
class Login:
    settings: Settings
    #: what the page says when the console's user may write (empty when it has its own)
    notice: str = ""


def login() -> Login:
    """The Neo4j user the console runs as (see the module docstring)."""
    main = settings()
    env = os.environ
    if user := env.get("ROBOTALE_CONSOLE_USER"):
        password = env.get("ROBOTALE_CONSOLE_PASSWORD", "")
        return Login(Settings(main.uri, user, password, main.from_env))
    if not main.from_env:
        user, password = LocalServer().console_credentials()
        return Login(Settings(main.uri, user, password, False))
    return Login(main, own_user_notice(main))


def own_user_notice(main: Settings | None = None) -> str:
    """How to give the console a reader of its own, when it would log in as robotale's own
    user (a server of ``NEO4J_URI`` without ``ROBOTALE_CONSOLE_USER``); "" otherwise."""
    main = main or settings()
    if os.environ.get("ROBOTALE_CONSOLE_USER") or not main.from_env:
        return ""
    return (
        f"The console logs in as {main.user!r}, robotale's own user: on a server with roles, "
        "create a reader (CREATE USER console SET PASSWORD '…'; GRANT ROLE reader TO console) "
        "and set ROBOTALE_CONSOLE_USER and ROBOTALE_CONSOLE_PASSWORD."
    )


def run(
    text: str,
    parameters: dict[str, Any],
    web: WebSettings,
    pool: Pool,
    watchdog_driver: Callable[[], Driver],
) -> list[dict[str, Any]]:
    """Run a console request on one of ``pool``'s capped workers; the results as JSON-ready
    dicts. A request that does not answer in time is the watchdog's (with robotale's own
    connection, ``watchdog_driver``), and the user reads what became of it."""
    where = login().settings
    request = {
        "id": uuid.uuid4().hex,
        "uri": where.uri,
        "user": where.user,
        "password": where.password,
        "database": database(),
        "text": text,
        "parameters": parameters,
        "rows": web.console_row_limit,
        "bytes": web.console_byte_limit,
        "timeout": web.console_timeout,
    }
    try:
        reply = pool.ask(request, web.console_timeout + web.console_grace, web.console_timeout)
    except queue.Empty:
        raise InputError(
            f"The console is busy ({pool.capacity} queries are running): try again in a moment."
        ) from None
    except NoAnswer:
        outcome = console_watchdog.stop(watchdog_driver(), request["id"])
        raise InputError(console_watchdog.sentence(outcome, web.console_timeout)) from None
    except Died as died:
        if died.memory:
            raise InputError(_too_large(web)) from None
        raise InputError(f"The console could not run the query ({died.last_line}).") from None
    if "error" in reply:
        if reply["kind"] == "MemoryError":
            raise InputError(_too_large(web))
        raise _ERRORS.get(reply["kind"], InputError)(reply["error"])
    return reply["results"]


def _too_large(web: WebSettings) -> str:
    return (
        f"The answer does not fit the console's {web.console_memory_mb} MB: narrow the query "
        "(a LIMIT, fewer or smaller values)."
    )


#: the files of ``cypher/`` that ask an analyst's questions of an EKG; robotale's own queries
#: (which build and read the graph) stay there but are not offered as examples
EXAMPLE_PREFIX = "ask_"


def examples() -> list[Example]:
    """The analyst's queries of ``cypher/``, each with its leading comment as description."""
    found = []
    for resource in sorted(files("robotale.cypher").iterdir(), key=lambda r: r.name):
        if not (resource.name.startswith(EXAMPLE_PREFIX) and resource.name.endswith(".cypher")):
            continue
        text = resource.read_text(encoding="utf-8")
        comment = []
        for line in text.splitlines():
            if not line.lstrip().startswith("//"):
                break
            comment.append(line.lstrip()[2:].strip())
        found.append(
            Example(
                name=resource.name.removesuffix(".cypher"),
                description=" ".join(comment),
                text=text,
                parameters=sorted(set(_PARAMETER.findall(text))),
            )
        )
    return found
