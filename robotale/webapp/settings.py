"""How the dashboard runs, from environment variables (every one has a sensible default).

``ROBOTALE_UPLOAD_LIMIT_MB`` (default 500) caps one upload; uploads wait in
``$ROBOTALE_HOME/uploads`` (``ROBOTALE_UPLOAD_DIR``) under generated names until they are
ingested, and are deleted then. BPMN models shown on the Model page are kept in
``$ROBOTALE_HOME/models`` (``ROBOTALE_MODEL_DIR``). ``ROBOTALE_SECRET_KEY`` signs sessions
and CSRF tokens; without it every start picks a random one (forms of an earlier run then ask
to be sent again).

``ROBOTALE_ALLOWED_HOSTS`` (comma-separated names) are the host names the dashboard answers
to besides ``localhost``, ``127.0.0.1`` and ``::1``: a request whose ``Host`` header names
another is refused, so a web page cannot reach the dashboard by pointing a name of its own at
this machine (DNS rebinding). Add the names it is reached by when it serves a network or runs in
a container reached by name; ``*`` turns the check off.
"""

from __future__ import annotations

import os
import secrets
from dataclasses import dataclass
from pathlib import Path

from robotale.config import robotale_home
from robotale.errors import InputError

DEFAULT_HOST = "127.0.0.1"
DEFAULT_PORT = 5000
#: the names a dashboard on this machine is reached by
LOCAL_HOSTS = ("localhost", "127.0.0.1", "::1")


@dataclass(frozen=True)
class WebSettings:
    upload_dir: Path
    model_dir: Path
    upload_limit_mb: int = 500
    secret_key: str = ""
    #: rows the Cypher console shows at most (the rest is counted, not sent)
    console_row_limit: int = 1000
    #: seconds a console query may run
    console_timeout: float = 30.0
    #: bytes of JSON the console sends at most (rows past them are counted, not sent)
    console_byte_limit: int = 5_000_000
    #: megabytes a process that runs console queries may grow by
    console_memory_mb: int = 256
    #: processes that run console queries at once (ROBOTALE_CONSOLE_WORKERS)
    console_workers: int = 4
    #: seconds past the timeout before the watchdog ends a query Neo4j did not stop
    console_grace: float = 10.0
    #: host names the dashboard answers to ("*": any)
    allowed_hosts: tuple[str, ...] = LOCAL_HOSTS

    @classmethod
    def from_env(cls) -> WebSettings:
        env = os.environ
        return cls(
            upload_dir=Path(env.get("ROBOTALE_UPLOAD_DIR") or robotale_home() / "uploads"),
            model_dir=Path(env.get("ROBOTALE_MODEL_DIR") or robotale_home() / "models"),
            upload_limit_mb=_megabytes(env.get("ROBOTALE_UPLOAD_LIMIT_MB"), cls.upload_limit_mb),
            secret_key=env.get("ROBOTALE_SECRET_KEY") or secrets.token_hex(32),
            allowed_hosts=_hosts(env.get("ROBOTALE_ALLOWED_HOSTS")),
            console_workers=_count(env.get("ROBOTALE_CONSOLE_WORKERS"), cls.console_workers),
        )


def _hosts(value: str | None) -> tuple[str, ...]:
    # The names of this machine always stay: a remote name adds to them.
    named = (name.strip().strip("[]").lower() for name in (value or "").split(","))
    return LOCAL_HOSTS + tuple(name for name in named if name and name not in LOCAL_HOSTS)


def _count(value: str | None, default: int) -> int:
    if not value:
        return default
    if not value.strip().isdigit() or int(value) < 1:
        raise InputError(f"ROBOTALE_CONSOLE_WORKERS is {value!r}: give a whole number, 1 or more.")
    return int(value)


def _megabytes(value: str | None, default: int) -> int:
    if not value:
        return default
    if not value.strip().isdigit() or int(value) < 1:
        raise InputError(
            f"ROBOTALE_UPLOAD_LIMIT_MB is {value!r}: give a whole number of megabytes."
        )
    return int(value)
