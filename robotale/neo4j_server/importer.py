"""Neo4j's offline bulk importer (``neo4j-admin database import full``) for the local server.

The importer writes a database's store files directly (no transactions, no queries), which is
several times faster than writing the same graph through Cypher, but only while the server is
stopped. :func:`import_offline` stops the local server, moves the database's current files
aside, imports, and starts the server again with the options it ran with; if the importer
fails, the files moved aside are put back, so the database is as it was before.
"""

from __future__ import annotations

import os
import re
import shutil
import subprocess
import time
import uuid
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from pathlib import Path

from robotale.errors import ServerError
from robotale.neo4j_server.jars import ensure_jars, release
from robotale.neo4j_server.server import ADMIN_TOOL, LocalServer, ServerOptions, java_executable
from robotale.timings import stage

#: where the database's files are moved while an import replaces them, under ``data/``
_ASIDE = "before-import"
#: the folders of ``data/`` that hold one database's files
_STORE_FOLDERS = ("databases", "transactions")


class RestartFailed(ServerError):
    """The local server did not start again after an import."""


@dataclass(frozen=True)
class ImportFiles:
    """The importer's input: CSV files with a header line each, by label or type."""

    nodes: Sequence[tuple[str, Path]]
    relationships: Sequence[tuple[str, Path]]
    #: fields may hold line breaks (the importer then reads each file on one thread)
    multiline: bool = False
    #: the node and relationship counts the files hold, checked against the importer's report
    expected: tuple[int, int] | None = None
    options: Sequence[str] = field(default_factory=tuple)
    #: the nodes' ids are 0, 1, 2 ... across all node files, each once
    dense_ids: bool = False


@dataclass(frozen=True)
class ImportReport:
    """What the importer said it did."""

    seconds: float  # its own "IMPORT DONE in" time
    nodes: int
    relationships: int
    properties: int


def admin_command(java: str, classpath: str, database: str, files: ImportFiles) -> list[str]:
    """The ``neo4j-admin database import full`` command line for ``files``."""
    command = [java, "-cp", classpath, ADMIN_TOOL, "database", "import", "full", database]
    # dense ids are the node ids themselves: the importer then builds no map from ids to nodes
    id_type = "actual" if files.dense_ids else "integer"
    command += ["--overwrite-destination=true", f"--id-type={id_type}", "--bad-tolerance=0"]
    command += [f"--nodes={label}={path}" for label, path in files.nodes]
    command += [f"--relationships={kind}={path}" for kind, path in files.relationships]
    if files.multiline:
        command.append("--multiline-fields=true")
    return [*command, *files.options]


def admin_environment(home: Path) -> dict[str, str]:
    """The environment the admin tool finds a server's home and configuration in."""
    return os.environ | {"NEO4J_HOME": str(home), "NEO4J_CONF": str(home / "conf")}


def parse_report(stdout: str) -> ImportReport | None:
    """The importer's own time and counts from its closing report (None: no such report)."""
    took = re.search(r"IMPORT DONE in ((?:\d+h )?(?:\d+m )?(?:\d+s )?\d+ms)", stdout)
    counts = [
        re.search(rf"(\d+) {what}\b", stdout) for what in ("nodes", "relationships", "properties")
    ]
    if took is None or None in counts:
        return None
    units = {"h": 3600.0, "m": 60.0, "s": 1.0, "ms": 0.001}
    own = sum(
        float(number) * units[unit] for number, unit in re.findall(r"(\d+)(h|ms|m|s)", took[1])
    )
    nodes, relationships, properties = (int(match[1]) for match in counts if match is not None)
    return ImportReport(own, nodes, relationships, properties)


def import_offline(
    server: LocalServer,
    database: str,
    files: ImportFiles,
    progress: Callable[[str], None] = lambda line: None,
) -> ImportReport:
    """Replace ``database`` of the running local ``server`` by the graph of ``files``.

    The server is stopped, the database's files moved aside, the importer run, and the server
    started again with the options it ran with. A failed import puts the files moved aside back
    before the restart: the database is then as it was. A :class:`ServerError` in one sentence
    when the import failed, a :class:`RestartFailed` when the server did not start again.
    """
    options = server.running_options()
    data = server.home / "data"
    aside = data / f"{_ASIDE}-{uuid.uuid4().hex[:8]}"
    progress("Stopping the local Neo4j for the import ...")
    with stage("stop the server"):
        server.stop()
    _move_aside(data, aside, database)
    try:
        with stage("the offline importer"):
            report = _run_importer(server, options.version, database, files, progress)
    except BaseException as error:
        _put_back(data, aside, database)
        _restart(server, options, progress, f"after the failed import ({error})")
        raise
    shutil.rmtree(aside, ignore_errors=True)
    with stage("start the server again"):
        _restart(server, options, progress, "after the import")
    return report


def _run_importer(
    server: LocalServer,
    version: str,
    database: str,
    files: ImportFiles,
    progress: Callable[[str], None],
) -> ImportReport:
    chosen = release(version)
    java, lib = java_executable(chosen), ensure_jars(release=chosen)
    plugins = server.plugins_folder(server.running_options())
    # the plugins' settings in neo4j.conf are only known with the plugins on the class path
    classpath = f"{lib}/*:{plugins}/*" if plugins else f"{lib}/*"
    command = admin_command(java, classpath, database, files)
    report_file = server.home / "logs" / "import.report"
    command.append(f"--report-file={report_file}")
    progress(f"Importing with neo4j-admin database import full into {database!r} ...")
    started = time.perf_counter()
    result = subprocess.run(
        command,
        env=admin_environment(server.home),
        cwd=server.home,
        capture_output=True,
        text=True,
        check=False,
    )
    (server.home / "logs" / "import.log").write_text(result.stdout + result.stderr)
    report = parse_report(result.stdout) if result.returncode == 0 else None
    if report is None:
        raise ServerError(
            f"neo4j-admin could not import the graph ({_gist(result.stdout + result.stderr)}; "
            f"its output is in {server.home / 'logs' / 'import.log'})"
        )
    if files.expected is not None and (report.nodes, report.relationships) != files.expected:
        raise ServerError(
            f"neo4j-admin imported {report.nodes:,} nodes and {report.relationships:,} "
            f"relationships, not the {files.expected[0]:,} and {files.expected[1]:,} written"
        )
    progress(
        f"Imported {report.nodes:,} nodes and {report.relationships:,} relationships in "
        f"{time.perf_counter() - started:.1f} s."
    )
    return report


def _gist(output: str) -> str:
    """The importer's reason in one line: its first error line, else its last line."""
    lines = [line.strip() for line in output.splitlines() if line.strip()]
    for line in lines:
        if "exception" in line.lower() or "error" in line.lower():
            return line[:300]
    return lines[-1][:300] if lines else "no output"


def _move_aside(data: Path, aside: Path, database: str) -> None:
    for folder in _STORE_FOLDERS:
        current = data / folder / database
        if current.exists():
            (aside / folder).mkdir(parents=True, exist_ok=True)
            current.rename(aside / folder / database)


def _put_back(data: Path, aside: Path, database: str) -> None:
    for folder in _STORE_FOLDERS:
        written = data / folder / database
        if written.exists():
            shutil.rmtree(written)
        kept = aside / folder / database
        if kept.exists():
            kept.rename(written)
    shutil.rmtree(aside, ignore_errors=True)


def _restart(
    server: LocalServer, options: ServerOptions, progress: Callable[[str], None], when: str
) -> None:
    progress("Starting the local Neo4j again ...")
    try:
        # the build goes on with queries: the Browser may finish starting meanwhile
        server.start(options, progress=progress, bolt_only=True)
    except ServerError as error:
        raise RestartFailed(
            f"The local Neo4j did not start again {when}: {error} Start it with "
            "`robotale neo4j start`."
        ) from error
