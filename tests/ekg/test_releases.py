"""The Neo4j releases the local server runs: their names, pinned jars and Java, a home's data
kept with the release that wrote it, and the newest release started by the real command and
building the thesis' log as the session's server does."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest
from neo4j import GraphDatabase

from robotale.ekg.build import build_ekg
from robotale.ekg.logs import log_summary
from robotale.errors import ServerError
from robotale.neo4j_server import jars, java
from robotale.neo4j_server.server import LocalServer, free_port

ROBOTALE = [sys.executable, "-m", "robotale"]
NEWEST = list(jars.RELEASES.values())[-1]


def test_a_release_is_named_by_its_line_or_its_version(monkeypatch):
    monkeypatch.delenv(jars.VERSION_ENV, raising=False)
    assert jars.release() is jars.DEFAULT_RELEASE
    assert jars.DEFAULT_RELEASE.line == "5.26"
    assert jars.release("2026.08").version == "2026.08.1"
    assert jars.release("5.26.30").line == "5.26"
    monkeypatch.setenv(jars.VERSION_ENV, "2026.08")
    assert jars.release() is NEWEST
    with pytest.raises(
        ServerError, match=r"robotale runs no Neo4j '4.4'; it runs 5.26 \(5.26.30\), 2026.08"
    ):
        jars.release("4.4")


@pytest.mark.parametrize("line", list(jars.RELEASES))
def test_each_release_pins_its_own_server_jars(line):
    chosen = jars.RELEASES[line]
    pinned = {f"{jar.group}:{jar.artifact}": jar for jar in jars.read_lock(chosen.lock)}
    assert pinned["org.neo4j:neo4j"].version == chosen.version
    assert pinned["org.neo4j.app:neo4j-server"].version == chosen.version
    assert pinned["org.neo4j.client:neo4j-browser"].version == chosen.browser
    assert all(len(jar.sha1) == 40 and jar.size > 0 for jar in pinned.values())
    assert chosen.lock.read_text().startswith(f"# Neo4j {chosen.version} Community server")


def _java_home(root: Path, name: str, version: str, release_file: bool = True) -> Path:
    """A Java home: its ``release`` file, or a ``java`` that says its version as Java does."""
    home = root / name
    (home / "bin").mkdir(parents=True)
    executable = home / "bin" / "java"
    said = f'openjdk version "{version}" 2025-01-21'
    executable.write_text(f"#!/bin/sh\necho '{said}' >&2\n")
    executable.chmod(0o755)
    if release_file:
        (home / "release").write_text(f'IMPLEMENTOR="Test"\nJAVA_VERSION="{version}"\n')
    return home


def test_the_java_a_release_runs_on_is_found(tmp_path, monkeypatch):
    roots = tmp_path / "jvm"
    old = _java_home(roots, "jdk-17", "17.0.12")
    _java_home(roots, "jdk-25", "25.0.1")
    _java_home(roots, "jdk-21", "21.0.4", release_file=False)  # asked instead
    monkeypatch.setattr(java, "JVM_ROOTS", (roots,))
    monkeypatch.setenv("PATH", str(tmp_path / "nothing"))
    monkeypatch.delenv("JAVA_HOME", raising=False)
    assert java.find_java(21, 21, "Neo4j x").executable == roots / "jdk-21" / "bin" / "java"
    assert java.find_java(21, 25, "Neo4j x").version == 25  # the newest first
    monkeypatch.setenv("JAVA_HOME", str(old))
    assert java.find_java(17, 21, "Neo4j x").executable == old / "bin" / "java"
    # JAVA_HOME is looked at first, but a Java the release does not run on is passed over
    assert java.find_java(21, 25, "Neo4j x").version == 25
    with pytest.raises(ServerError) as refused:
        java.find_java(26, 27, "Neo4j 2027.01.0")
    message = str(refused.value)
    assert message.startswith("Neo4j 2027.01.0 needs Java 26 to 27 and none was found")
    assert f"Java 17 ({old / 'bin' / 'java'})" in message and "Java 25" in message


def test_data_stays_with_the_release_that_wrote_it(tmp_path):
    server = LocalServer(tmp_path)
    server._require_data_of(jars.DEFAULT_RELEASE)  # an empty home takes any release
    assert server.version_file.read_text() == jars.DEFAULT_RELEASE.version
    (server.home / "data" / "dbms").mkdir(parents=True)
    (server.home / "data" / "dbms" / "auth.ini").write_text("x")
    with pytest.raises(ServerError) as refused:
        server._require_data_of(NEWEST)
    assert str(refused.value) == (
        f"The Neo4j data in {server.home / 'data'} was written by Neo4j "
        f"{jars.DEFAULT_RELEASE.version}, not {NEWEST.version}: start it with --version "
        f"{jars.DEFAULT_RELEASE.version}, or move that folder away to start Neo4j "
        f"{NEWEST.version} with an empty database."
    )


@pytest.mark.slow
def test_the_newest_release_started_by_the_command_builds_the_log_as_the_suites_server(
    env, tmp_path, neo4j_driver, log_name, thesis_log
):
    """`robotale neo4j start --version` with the newest release, then the thesis' log built
    on it and on the session's server: the same graph, counted in each."""
    started = subprocess.run(
        [
            *ROBOTALE,
            "neo4j",
            "start",
            "--version",
            NEWEST.line,
            "--bolt-port",
            str(free_port()),
            "--http-port",
            str(free_port()),
        ],
        env=env,
        capture_output=True,
        text=True,
        timeout=600,
    )
    try:
        assert started.returncode == 0, started.stderr
        assert f"Neo4j {NEWEST.version} is running at" in started.stdout
        server = LocalServer(Path(env["ROBOTALE_HOME"]))
        running = server.running()
        assert running is not None
        with GraphDatabase.driver(running.bolt_uri, auth=("neo4j", server.password())) as newest:
            records, _, _ = newest.execute_query("CALL dbms.components() YIELD versions")
            assert records[0]["versions"] == [NEWEST.version]
            build_ekg(newest, thesis_log, log_name, progress=False)
            counts = log_summary(newest, log_name)["counts"]
        build_ekg(neo4j_driver, thesis_log, log_name, progress=False)
        assert log_summary(neo4j_driver, log_name)["counts"] == counts
        assert counts["events"] == len(thesis_log)
    finally:
        stopped = subprocess.run(
            [*ROBOTALE, "neo4j", "stop"], env=env, capture_output=True, text=True, timeout=300
        )
    assert stopped.returncode == 0
