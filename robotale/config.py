"""Where robotale keeps its files, configured by environment variables.

``ROBOTALE_HOME`` (default ``~/.robotale``) holds the local Neo4j server and its state;
``ROBOTALE_CACHE`` (default ``$ROBOTALE_HOME/cache``) holds downloads that never change for a
pinned version (the Neo4j jars), so several homes -- a test run's, a user's -- can share one.
"""

import os
from pathlib import Path


def robotale_home() -> Path:
    """The directory for robotale's state (local Neo4j data, logs, pid)."""
    return Path(os.environ.get("ROBOTALE_HOME") or Path.home() / ".robotale").expanduser()


def cache_dir() -> Path:
    """The directory for pinned downloads shared between homes."""
    configured = os.environ.get("ROBOTALE_CACHE")
    return Path(configured).expanduser() if configured else robotale_home() / "cache"
