"""The local server's ``neo4j.conf``: robotale's settings, the user's overlay, plugins.

Every start writes ``<robotale home>/neo4j/conf/neo4j.conf`` from three sources: the settings
robotale must own (where it listens, authentication, where its data, logs and plugins are),
the defaults it chooses (a user may change them), and the user's overlay
``<robotale home>/neo4j.conf``, which a start only reads. An overlay line that tries to change
a setting robotale owns is ignored with a one-line warning. ``server.jvm.additional`` lines
of the overlay reach the JVM, since robotale starts java itself rather than Neo4j's launcher.
``apoc.conf`` in the robotale home is copied beside ``neo4j.conf`` (APOC 5 reads its settings
only from there).
"""

from __future__ import annotations

import zipfile
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

from robotale.errors import ServerError

#: functions of plugins a query may call besides Neo4j's built-in ones (none so far: add
#: a name here only for a function that reads and returns a bounded value)
ALLOWED_FUNCTIONS: frozenset[str] = frozenset()

OVERLAY_NAME = "neo4j.conf"
APOC_CONF_NAME = "apoc.conf"
PLUGINS_NAME = "plugins"
JVM_ADDITIONAL = "server.jvm.additional"

#: What an overlay may not change, and why (the end of the warning line).
OWNED = {
    "server.default_listen_address": "robotale listens on 127.0.0.1 only",
    "server.default_advertised_address": "robotale listens on 127.0.0.1 only",
    "server.bolt.listen_address": "use --bolt-port",
    "server.bolt.advertised_address": "use --bolt-port",
    "server.bolt.enabled": "robotale talks Bolt",
    "server.http.listen_address": "use --http-port",
    "server.http.advertised_address": "use --http-port",
    "server.http.enabled": "robotale waits for HTTP and serves Neo4j Browser on it",
    "server.memory.pagecache.size": "use --pagecache",
    "server.memory.heap.initial_size": "use --heap",
    "server.memory.heap.max_size": "use --heap",
    "dbms.security.auth_enabled": "robotale's server always asks for a password",
    "server.directories.data": "robotale keeps the data under its home",
    "server.directories.logs": "robotale reads the server's log under its home",
    "server.directories.import": "robotale keeps the import folder under its home",
    "server.directories.plugins": "use --plugins or the plugins folder of the robotale home",
}


@dataclass(frozen=True)
class Overlay:
    """The user's settings (in file order) and the JVM options among them."""

    settings: dict[str, str]
    jvm_options: tuple[str, ...]


def read_overlay(path: Path, warn: Callable[[str], None]) -> Overlay:
    """The settings of ``path`` (empty when there is no such file); ``warn`` hears of every
    line that tries to change a setting robotale owns."""
    if not path.is_file():
        return Overlay({}, ())
    settings: dict[str, str] = {}
    jvm_options: list[str] = []
    for number, line in enumerate(path.read_text(errors="replace").splitlines(), start=1):
        text = line.strip()
        if not text or text.startswith("#"):
            continue
        key, equals, value = text.partition("=")
        key = key.strip()
        if not equals or not key:
            raise ServerError(
                f"{path} line {number} is not a setting: write name=value (or # a comment)."
            )
        if key in OWNED:
            warn(f"{path} line {number}: {key} is ignored ({OWNED[key]}).")
        elif key == JVM_ADDITIONAL:
            jvm_options.append(value.strip())
        else:
            settings[key] = value.strip()
    return Overlay(settings, tuple(jvm_options))


def check_plugins(folder: Path) -> list[Path]:
    """The plugin jars of ``folder``; anything else in it is refused in one sentence."""
    if not folder.is_dir():
        what = "is not a folder" if folder.exists() else "does not exist"
        raise ServerError(f"The Neo4j plugins folder {folder} {what}.")
    jars = []
    for entry in sorted(folder.iterdir()):
        if entry.name.startswith("."):
            continue  # editors' and file managers' own files
        if entry.suffix != ".jar" or not entry.is_file():
            raise ServerError(
                f"{entry} is not a jar; the Neo4j plugins folder {folder} may hold only .jar files."
            )
        if not zipfile.is_zipfile(entry):
            raise ServerError(f"The plugin {entry} is not a jar (it is no zip archive).")
        jars.append(entry)
    return jars


def compose(owned: dict[str, str], defaults: dict[str, str], overlay: Overlay) -> dict[str, str]:
    """The settings the server starts with: robotale's defaults, changed by the overlay,
    then robotale's own, which no overlay changes."""
    return {**defaults, **overlay.settings, **owned}


def render(settings: dict[str, str], overlay_path: Path) -> str:
    """The text of ``neo4j.conf``."""
    lines = [
        "# Written by `robotale neo4j start` on every start; edits here are overwritten.",
        f"# Put your own settings in {overlay_path} (read at every start, never rewritten).",
    ]
    lines += [f"{key}={value}" for key, value in settings.items()]
    return "\n".join(lines) + "\n"
