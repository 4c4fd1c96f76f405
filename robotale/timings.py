"""Where a command's time goes: its stages' wall and CPU times on stderr, when asked.

With ``ROBOTALE_TIMINGS`` set (to anything but empty or ``0``), each :func:`stage` a command
passes through prints one line to stderr when it ends::

    robotale timing: read the log: 1.2 s wall, 1.1 s CPU (+ 0.0 s in subprocesses; Neo4j 0.0 s)

CPU is this process's (``time.process_time``), its finished subprocesses' (the offline
importer, for one) and the Neo4j server's, whose process :func:`watch_server` names (read from
``/proc``, where there is one). Stages nest: an enclosing stage's line includes its inner
ones'. Without the variable a stage costs one dictionary lookup.
"""

from __future__ import annotations

import os
import sys
import time
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from pathlib import Path

ENVIRONMENT = "ROBOTALE_TIMINGS"

#: the Neo4j server's process id, or None while none runs (set by :func:`watch_server`)
_server: list[Callable[[], int | None]] = []

#: the watched server's CPU seconds when watching began, by its process id: a stage that
#: began before (the command's own, around the whole command) counts the server from then on,
#: not the CPU it spent starting and in earlier commands
_watched_from: dict[int, float] = {}


def enabled() -> bool:
    return os.environ.get(ENVIRONMENT, "") not in ("", "0")


def watch_server(pid: Callable[[], int | None]) -> None:
    """Count the CPU time of the server whose process id ``pid()`` gives (asked at each
    stage's start and end: a restart makes a new process, whose time counts from its start)."""
    _server[:] = [pid]
    began = _server_cpu() if enabled() else None
    _watched_from.clear()
    if began is not None:
        _watched_from[began[0]] = began[1]


@contextmanager
def stage(name: str) -> Iterator[None]:
    """Time the block as the stage ``name`` (nothing, unless :func:`enabled`)."""
    if not enabled():
        yield
        return
    wall, cpu, children = time.perf_counter(), time.process_time(), _children()
    server = _server_cpu()
    try:
        yield
    finally:
        spent_server = _server_spent(server, _server_cpu())
        print(
            f"robotale timing: {name}: {time.perf_counter() - wall:.2f} s wall, "
            f"{time.process_time() - cpu:.2f} s CPU (+ {_children() - children:.2f} s in "
            f"subprocesses; Neo4j {spent_server:.2f} s; load average "
            f"{os.getloadavg()[0]:.1f})",
            file=sys.stderr,
            flush=True,
        )


def _children() -> float:
    times = os.times()
    return times.children_user + times.children_system


def _server_cpu() -> tuple[int, float] | None:
    """(process id, CPU seconds so far) of the watched server, None when none runs."""
    pid = _server[0]() if _server else None
    if pid is None:
        return None
    seconds = process_seconds(pid)
    return None if seconds is None else (pid, seconds)


def _server_spent(before: tuple[int, float] | None, after: tuple[int, float] | None) -> float:
    if after is None:
        return 0.0
    if before is None or before[0] != after[0]:  # watched or started (again) within the stage
        return after[1] - _watched_from.get(after[0], 0.0)
    return after[1] - before[1]


def process_seconds(pid: int) -> float | None:
    """The CPU seconds (user and system) the process ``pid`` has used, None when unknown."""
    try:
        stat = Path(f"/proc/{pid}/stat").read_text()
    except OSError:
        return None
    fields = stat.rsplit(")", 1)[1].split()
    return (int(fields[11]) + int(fields[12])) / os.sysconf("SC_CLK_TCK")
