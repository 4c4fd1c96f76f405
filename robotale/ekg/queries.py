"""Load the Cypher files of ``cypher/`` (installed as the package ``robotale.cypher``)."""

from __future__ import annotations

import re
from functools import cache
from importlib.resources import files


@cache
def cypher(name: str) -> str:
    """The text of ``cypher/<name>.cypher``."""
    return (files("robotale.cypher") / f"{name}.cypher").read_text(encoding="utf-8")


def statements(name: str) -> list[str]:
    """The statements of a file that holds several, each ending in ``;`` at the end of a line."""
    text = "\n".join(
        line for line in cypher(name).splitlines() if not line.lstrip().startswith("//")
    )
    return [part.strip() for part in re.split(r";[ \t]*(?:\n|$)", text) if part.strip()]
