"""Where Neo4j is and how to talk to it.

With ``NEO4J_URI`` set (plus ``NEO4J_USER``, default ``neo4j``, and ``NEO4J_PASSWORD``)
robotale uses that server: docker compose, a cluster, Aura (``neo4j://`` and ``neo4j+s://``
give the routing driver a cluster needs; see docs/scale.md): what only reads goes through
:func:`read_rows` or a read session, so a cluster sends it to a follower. Otherwise it uses
the local server of ``robotale neo4j start`` (its port and generated password live under the
robotale home).
``NEO4J_DATABASE`` picks the database (default ``neo4j``).
"""

from __future__ import annotations

import logging
import os
from collections.abc import Iterator
from contextlib import contextmanager
from dataclasses import dataclass
from typing import Any

from neo4j import Driver, GraphDatabase, Record, RoutingControl
from neo4j.exceptions import AuthError, ServiceUnavailable

from robotale.errors import ServerError
from robotale.neo4j_server.server import CRASHED, HOST, OTHER, RUNNING, USER, LocalServer
from robotale.neo4j_server.server import (
    bolt_answers as bolt_answers,  # re-exported: the server owns it
)
from robotale.queries import cypher

# The driver logs every refused connection attempt and every connection a server dropped
# (as errors, on stderr); robotale turns the failure into one sentence instead.
logging.getLogger("neo4j").setLevel(logging.CRITICAL)


@dataclass(frozen=True)
class Settings:
    uri: str
    user: str
    password: str
    from_env: bool  # True when NEO4J_URI chose the server

    @property
    def auth(self) -> tuple[str, str]:
        return (self.user, self.password)


def database() -> str:
    """The Neo4j database robotale uses (``NEO4J_DATABASE``, default ``neo4j``)."""
    return os.environ.get("NEO4J_DATABASE") or "neo4j"


def settings() -> Settings:
    """The server robotale talks to, from the environment or the local server's records."""
    if uri := os.environ.get("NEO4J_URI"):
        user = os.environ.get("NEO4J_USER") or USER
        return Settings(uri, user, os.environ.get("NEO4J_PASSWORD", ""), True)
    server = LocalServer()
    running = server.running()
    port = running.bolt_port if running else server.recorded_options().bolt_port
    return Settings(f"bolt://{HOST}:{port}", USER, server.password() or "", False)


def connect(where: Settings | None = None, user_agent: str | None = None) -> Driver:
    """A driver for the server that answers; a :class:`ServerError` saying what to do if not.
    ``user_agent`` names its connections to the server (see :func:`client_connections`)."""
    where = where or settings()
    if not where.from_env:
        _require_local_server()
    if user_agent:
        driver = GraphDatabase.driver(
            where.uri, auth=where.auth, connection_timeout=5, user_agent=user_agent
        )
    else:  # the driver's own user agent
        driver = GraphDatabase.driver(where.uri, auth=where.auth, connection_timeout=5)
    try:
        driver.verify_connectivity()
    except AuthError:
        driver.close()
        raise ServerError(
            f"Neo4j at {where.uri} refused user {where.user!r}: set NEO4J_USER and "
            "NEO4J_PASSWORD to that server's credentials."
        ) from None
    except (ServiceUnavailable, OSError):
        driver.close()
        raise ServerError(unreachable_message(where)) from None
    return driver


@contextmanager
def session_driver(
    where: Settings | None = None, user_agent: str | None = None
) -> Iterator[Driver]:
    """:func:`connect` as a context manager that closes the driver."""
    driver = connect(where, user_agent)
    try:
        yield driver
    finally:
        driver.close()


def _require_local_server() -> None:
    """Refuse before connecting when the local server is not running: whatever answers on
    its port then is not robotale's server (and its password is not for that one)."""
    server = LocalServer()
    state = server.condition()
    if state.condition == RUNNING:
        return
    record = state.record
    port = record.bolt_port if record else server.recorded_options().bolt_port
    if state.condition == CRASHED and record is not None:
        raise ServerError(
            f"The local Neo4j (pid {record.pid}, bolt port {port}) has crashed: start it again "
            "with `robotale neo4j start`."
        )
    if state.condition == OTHER:
        raise ServerError(
            f"The local Neo4j is not running and something else answers on its bolt port {port}:"
            " robotale does not use it; set NEO4J_URI to use that server, or stop it and run "
            "`robotale neo4j start`."
        )
    raise ServerError(unreachable_message(Settings(f"bolt://{HOST}:{port}", USER, "", False)))


def unreachable_message(where: Settings) -> str:
    if where.from_env:
        return (
            f"Neo4j is not reachable at {where.uri} (NEO4J_URI): start that server, or unset "
            "NEO4J_URI and run `robotale neo4j start`."
        )
    return (
        f"Neo4j is not running at {where.uri}: start it with `robotale neo4j start`, "
        "or set NEO4J_URI to a running server."
    )


def read_rows(driver: Driver, query: str, **parameters: Any) -> list[dict[str, Any]]:
    """The rows of ``query``, which only reads, in a read transaction: a cluster routes it to
    a follower (the driver's bookmarks still make it see this process's own writes), and
    Neo4j refuses it should it ever write."""
    records, _, _ = driver.execute_query(
        query, parameters, database_=database(), routing_=RoutingControl.READ
    )
    return [_row(record) for record in records]


def read_autocommit(driver: Driver, query: str, parameters: dict[str, Any]) -> list[Record]:
    """The records of ``query``, which only reads, run as an auto-commit transaction on the
    leader: one round trip, where ``execute_query``'s managed transaction costs a second
    (its commit). For a writer's reads of what no other writer changes (it holds the log's
    lock), so there is nothing a retry would be for."""
    with driver.session(database=database()) as session:
        return list(session.run(query, parameters))


#: values a record holds as they are: the driver's own conversion (``Record.data``) would walk
#: a byte array byte by byte (a recorded Arrow schema: thousands of calls per read)
_AS_THEY_ARE = (str, int, float, bool, bytes, bytearray, type(None))


def _row(record: Record) -> dict[str, Any]:
    """``record.data()``, with the values that need no conversion taken as they are."""
    return {
        key: value if isinstance(value, _AS_THEY_ARE) else record.data(key)[key]
        for key, value in zip(record.keys(), record, strict=True)
    }


def client_connections(driver: Driver, user_agent: str) -> list[dict[str, Any]]:
    """The server's client connections other than those named ``user_agent``."""
    return read_rows(driver, cypher("ekg_client_connections"), agent=user_agent)


def server_version(driver: Driver) -> dict[str, Any]:
    """Name, version and edition of the server behind ``driver``."""
    records, _, _ = driver.execute_query(cypher("ekg_server_version"), routing_=RoutingControl.READ)
    return records[0].data()
