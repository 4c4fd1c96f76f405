"""How the dashboard runs, from environment variables (every one has a sensible default).

``ROBOTALE_UPLOAD_LIMIT_MB`` (default 500) caps one upload; uploads wait in
``$ROBOTALE_HOME/uploads`` (``ROBOTALE_UPLOAD_DIR``) under generated names until they are
ingested, and are deleted then. BPMN models shown on the Model page are kept in
``$ROBOTALE_HOME/models`` (``ROBOTALE_MODEL_DIR``). ``ROBOTALE_SECRET_KEY`` signs sessions
and CSRF tokens; without it every start picks a random one (forms of an earlier run then ask
to be sent again).
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

    @classmethod
    def from_env(cls) -> WebSettings:
        env = os.environ
        return cls(
            upload_dir=Path(env.get("ROBOTALE_UPLOAD_DIR") or robotale_home() / "uploads"),
            model_dir=Path(env.get("ROBOTALE_MODEL_DIR") or robotale_home() / "models"),
            upload_limit_mb=_megabytes(env.get("ROBOTALE_UPLOAD_LIMIT_MB"), cls.upload_limit_mb),
            secret_key=env.get("ROBOTALE_SECRET_KEY") or secrets.token_hex(32),
        )


def _megabytes(value: str | None, default: int) -> int:
    if not value:
        return default
    if not value.strip().isdigit() or int(value) < 1:
        raise InputError(
            f"ROBOTALE_UPLOAD_LIMIT_MB is {value!r}: give a whole number of megabytes."
        )
    return int(value)
