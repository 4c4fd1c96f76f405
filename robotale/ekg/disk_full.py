"""Whether a write failed because the disk under robotale's local Neo4j filled up.

Neo4j answers such a write with a generic error ("Could not apply the transaction ... to the
store") and stops the database until it is restarted; only its own debug log names the cause,
the store file it could not grow and the size it asked for. For robotale's local server that
log is in its home, so the cause can be said in one true sentence; a server of ``NEO4J_URI``
keeps its log elsewhere, and its error is said as Neo4j gave it.
"""

from __future__ import annotations

import os
import re
import shutil
from pathlib import Path

from robotale.ekg.connection import settings
from robotale.neo4j_server.server import LocalServer

#: what the operating system says, whichever file Neo4j was writing
_NO_SPACE = "No space left on device"
_OUT_OF_SPACE = re.compile(
    r"OutOfDiskSpaceException: System is out of disk space for store file at: (?P<file>\S+?)\."
    r"(?:(?!OutOfDiskSpaceException).)*?Requested file size: (?P<size>\d+)"
)


def debug_log() -> Path | None:
    """The local server's debug log (None for a server of ``NEO4J_URI``)."""
    if settings().from_env:
        return None
    return LocalServer().log_file.with_name("debug.log")


def log_position() -> int:
    """Where the debug log ends now: what a later write adds comes after it."""
    log = debug_log()
    try:
        return log.stat().st_size if log is not None else 0
    except OSError:
        return 0


def out_of_disk(since: int) -> str | None:
    """The sentence saying which disk filled and how much Neo4j asked for, when the local
    server's debug log says so after position ``since``; None otherwise."""
    log = debug_log()
    if log is None:
        return None
    try:
        with open(log, "rb") as file:
            file.seek(since)
            text = file.read().decode(errors="replace")
    except OSError:
        return None
    found = _OUT_OF_SPACE.search(text)
    if found is not None:
        store = Path(found.group("file"))
        asked = f"it could not grow {store.name} to {size_text(int(found.group('size')))}"
        return f"Neo4j's disk is full: {asked} on the disk of {_where(store.parent)}"
    if _NO_SPACE in text:  # a transaction log's write: Neo4j names neither file nor size
        data = log.parent.parent / "data"
        return f"Neo4j's disk is full: it could not write its data on the disk of {_where(data)}"
    return None


def _where(folder: Path) -> str:
    """The mount point of ``folder``, with what is free there."""
    if not folder.exists():
        return str(folder)
    usage = shutil.disk_usage(folder)
    return f"{_mount_point(folder)} ({size_text(usage.free)} of its {size_text(usage.total)} free)"


def _mount_point(path: Path) -> Path:
    path = path.resolve()
    while not os.path.ismount(path) and path != path.parent:
        path = path.parent
    return path


def size_text(count: int) -> str:
    """``count`` bytes as people read them (``1.5 GB``)."""
    for unit, size in (("GB", 1024**3), ("MB", 1024**2), ("kB", 1024)):
        if count >= size:
            return f"{count / size:.1f} {unit}"
    return f"{count} bytes"
