"""How long a test waits for what a busy machine does slowly (a process to start, a server to
answer, workers to join): the time it takes on an idle machine, stretched by how busy this one
is when the test waits.

The stretch is the load average over the cores (2 cores at load 20: ten times), never less
than one: a test that passes on an idle machine then passes on a busy one, and a wait that
never ends still fails, later.
"""

from __future__ import annotations

import os


def busy_factor() -> float:
    """How many runnable tasks share each core now (at least 1)."""
    return max(1.0, os.getloadavg()[0] / (os.cpu_count() or 1))


def patience(seconds: float) -> float:
    """``seconds`` (enough on an idle machine), stretched for this machine's load now."""
    return seconds * busy_factor()
