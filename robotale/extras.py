"""Optional extras: a command that needs one that is not installed says so in one sentence,
before it imports anything of it or writes anything."""

from __future__ import annotations

import importlib

from robotale.errors import InputError

#: per extra, what needs it and a module whose import proves it is installed
_EXTRAS = {
    "dds": (
        "one process per robot (--bus dds, fame node, record) needs Cyclone DDS",
        "cyclonedds.core",
    ),
}


def require(extra: str) -> None:
    """Raise one sentence naming ``pip install 'robotale[extra]'`` when ``extra`` is missing."""
    purpose, module = _EXTRAS[extra]
    try:
        # imported here, at the moment of asking, so that an extra installed (or hidden) since
        # the last call is seen
        importlib.import_module(module)
    except ImportError:
        raise InputError(f"{purpose}: pip install 'robotale[{extra}]'") from None
