"""The local server's ports, plugins and settings overlay, against real servers, real sockets
and the real APOC jar from Maven Central."""

from __future__ import annotations

import http.client
import subprocess
import sys
import time
from pathlib import Path

import pytest
from neo4j import GraphDatabase

from robotale.errors import ServerError
from robotale.neo4j_server import jars
from robotale.neo4j_server.server import (
    LocalServer,
    PortInUse,
    ServerOptions,
    collector,
    free_port,
    free_ports,
)
from robotale.neo4j_server.server_config import check_plugins, read_overlay

ROBOTALE = [sys.executable, "-m", "robotale"]
# A program other than robotale that holds a port until its stdin closes.
_HOLDER = (
    "import socket, sys\n"
    "s = socket.socket(); s.bind(('127.0.0.1', 0)); s.listen()\n"
    "print(s.getsockname()[1], flush=True); sys.stdin.read()\n"
)


@pytest.fixture
def held_port():
    """A port held by another process, and that process."""
    holder = subprocess.Popen(
        [sys.executable, "-c", _HOLDER], stdin=subprocess.PIPE, stdout=subprocess.PIPE, text=True
    )
    try:
        yield int(holder.stdout.readline()), holder
    finally:
        holder.stdin.close()
        holder.wait(timeout=10)


# -- ports -----------------------------------------------------------------------------------


def test_a_port_held_by_another_program_names_it_and_its_pid(tmp_path, held_port):
    port, holder = held_port
    server = LocalServer(tmp_path)
    with pytest.raises(PortInUse) as refused:
        server.start(ServerOptions(bolt_port=free_port(), http_port=port))
    message = str(refused.value)
    assert f"http port {port} on 127.0.0.1 is in use" in message
    command = Path(f"/proc/{holder.pid}/comm").read_text().strip()
    assert f"held by {command} (pid {holder.pid})" in message
    assert "\n" not in message
    assert server.running() is None


def test_the_cli_reports_the_held_port_in_one_line(env, held_port):
    port, holder = held_port
    result = _start(env, "--bolt-port", str(port), "--http-port", str(free_port()))
    assert result.returncode == 1
    lines = result.stderr.strip().splitlines()
    assert len(lines) == 1, result.stderr
    assert f"bolt port {port}" in lines[0] and f"(pid {holder.pid})" in lines[0]


@pytest.mark.slow
def test_start_right_after_stop_with_clients_connected(tmp_path, neo4j_server):
    server = LocalServer(tmp_path)
    options = ServerOptions(*free_ports(2), heap="512m", pagecache="64m")
    first = server.start(options)
    waits: list[str] = []
    try:
        # Clients still connected when the server stops leave the server's side of their
        # connections behind (FIN_WAIT/TIME_WAIT): that must not keep the ports.
        driver = GraphDatabase.driver(first.bolt_uri, auth=("neo4j", server.password() or ""))
        driver.execute_query("RETURN 1")
        browser = http.client.HTTPConnection("127.0.0.1", first.http_port)
        browser.request("GET", "/")
        browser.getresponse().read()
        assert server.stop() == first
        assert _ended(first.pid), "stop returned before the server's process was gone"
        began = time.monotonic()
        second = server.start(options, progress=waits.append)
        restart = time.monotonic() - began
        records, _, _ = GraphDatabase.driver(
            second.bolt_uri, auth=("neo4j", server.password() or "")
        ).execute_query("RETURN 6 * 7 AS answer")
        assert records[0]["answer"] == 42
        driver.close()
        browser.close()
    finally:
        server.stop()
    assert second.pid != first.pid and second.bolt_port == first.bolt_port
    assert waits == [], f"start waited for its ports ({restart:.0f} s): {waits}"


# -- plugins and the settings overlay, without a server -------------------------------------


def test_a_missing_plugins_folder_is_one_sentence(tmp_path):
    with pytest.raises(ServerError, match=rf"^The Neo4j plugins folder {tmp_path}/nope does not"):
        check_plugins(tmp_path / "nope")


def test_a_file_that_is_no_jar_in_the_plugins_folder_is_named(tmp_path):
    (tmp_path / "README.txt").write_text("apoc goes here")
    with pytest.raises(ServerError, match=r"README\.txt is not a jar; the Neo4j plugins folder"):
        check_plugins(tmp_path)
    (tmp_path / "README.txt").unlink()
    (tmp_path / "broken.jar").write_bytes(b"not a zip")
    with pytest.raises(ServerError, match=r"broken\.jar is not a jar \(it is no zip archive\)"):
        check_plugins(tmp_path)


def test_the_plugins_folder_of_the_home_is_used_when_present(tmp_path):
    server = LocalServer(tmp_path)
    assert server.plugins_folder(ServerOptions()) is None
    (tmp_path / "plugins").mkdir()
    assert server.plugins_folder(ServerOptions()) == (tmp_path / "plugins").resolve()
    chosen = tmp_path / "elsewhere"
    assert server.plugins_folder(ServerOptions(plugins=chosen)) == chosen.resolve()


def test_the_overlay_changes_defaults_but_not_what_robotale_owns(tmp_path):
    server = LocalServer(tmp_path)
    overlay = tmp_path / "neo4j.conf"
    text = (
        "# mine\n"
        "dbms.security.procedures.unrestricted=apoc.*\n"
        "db.tx_log.rotation.retention_policy=2 days\n"
        "server.default_listen_address=0.0.0.0\n"
        "dbms.security.auth_enabled=false\n"
        "server.jvm.additional=-Dmine=yes\n"
    )
    overlay.write_text(text)
    warnings: list[str] = []
    options = ServerOptions(*free_ports(2))
    server._write_config(options, read_overlay(overlay, warnings.append))
    written = _settings(server.home / "conf" / "neo4j.conf")
    assert written["dbms.security.procedures.unrestricted"] == "apoc.*"
    assert written["db.tx_log.rotation.retention_policy"] == "2 days"
    assert written["server.default_listen_address"] == "127.0.0.1"
    assert written["dbms.security.auth_enabled"] == "true"
    assert written["server.bolt.listen_address"] == f"127.0.0.1:{options.bolt_port}"
    assert "server.jvm.additional" not in written
    assert warnings == [
        f"{overlay} line 4: server.default_listen_address is ignored "
        "(robotale listens on 127.0.0.1 only).",
        f"{overlay} line 5: dbms.security.auth_enabled is ignored "
        "(robotale's server always asks for a password).",
    ]
    assert overlay.read_text() == text


def test_an_overlay_that_chooses_a_collector_replaces_robotales_choice():
    # the JVM refuses to start with two collectors chosen
    assert collector(()) == ("-XX:+UseParallelGC",)
    assert collector(("-Dmine=yes",)) == ("-XX:+UseParallelGC",)
    assert collector(("-XX:+UseG1GC",)) == ()
    assert collector(("-XX:+UseZGC", "-Dmine=yes")) == ()
    assert collector(("-XX:-UseG1GC",)) == ("-XX:+UseParallelGC",)


def test_an_overlay_line_that_is_no_setting_names_file_and_line(tmp_path):
    overlay = tmp_path / "neo4j.conf"
    overlay.write_text("dbms.security.procedures.unrestricted=apoc.*\napoc please\n")
    with pytest.raises(ServerError, match=rf"^{overlay} line 2 is not a setting"):
        read_overlay(overlay, print)


def test_the_cli_refuses_a_missing_plugins_folder_before_starting(env, tmp_path):
    missing = tmp_path / "no-plugins"
    result = _start(env, "--plugins", str(missing), "--bolt-port", str(free_port()))
    assert result.returncode == 1
    assert result.stderr.strip() == f"robotale: The Neo4j plugins folder {missing} does not exist."
    assert not (tmp_path / "home" / "neo4j" / "server.json").exists()


# -- a real plugin ---------------------------------------------------------------------------


@pytest.mark.slow
def test_apoc_from_maven_central_through_plugins_and_overlay(env, tmp_path):
    plugins = tmp_path / "plugins"
    plugins.mkdir()
    apoc = jars.plugin_jar("apoc-core")  # cached: later runs do not download it again
    (plugins / apoc.name).symlink_to(apoc)
    home = Path(env["ROBOTALE_HOME"])
    home.mkdir()
    overlay = home / "neo4j.conf"
    overlay.write_text(
        "dbms.security.procedures.unrestricted=apoc.*\n"
        "dbms.security.procedures.allowlist=apoc.*\n"
        "server.bolt.listen_address=0.0.0.0:7687\n"
        "server.jvm.additional=-Drobotale.overlay=read\n"
    )
    before = overlay.read_bytes()
    bolt = free_port()
    started = _start(
        env, "--plugins", str(plugins), "--bolt-port", str(bolt), "--http-port", str(free_port())
    )
    try:
        assert started.returncode == 0, started.stderr
        assert f"Plugins from {plugins.resolve()}: {apoc.name}" in started.stdout
        assert started.stderr.strip() == (
            f"{overlay} line 3: server.bolt.listen_address is ignored (use --bolt-port)."
        )
        server = LocalServer(home)
        running = server.running()
        assert running is not None and running.bolt_port == bolt
        cmdline = Path(f"/proc/{running.pid}/cmdline").read_bytes().split(b"\0")
        assert b"-Drobotale.overlay=read" in cmdline
        with GraphDatabase.driver(running.bolt_uri, auth=("neo4j", server.password())) as driver:
            records, _, _ = driver.execute_query("RETURN apoc.version() AS version")
            assert records[0]["version"] == apoc.name.split("-")[2]  # apoc-core-<version>-core
            records, _, _ = driver.execute_query(
                "CALL apoc.periodic.iterate('UNWIND range(1, 10) AS i RETURN i', "
                "'CREATE (:Probe {i: i})', {batchSize: 3}) YIELD total RETURN total"
            )
            assert records[0]["total"] == 10
            records, _, _ = driver.execute_query("MATCH (p:Probe) RETURN sum(p.i) AS s")
            assert records[0]["s"] == sum(range(1, 11))
    finally:
        stopped = subprocess.run(
            [*ROBOTALE, "neo4j", "stop"], env=env, capture_output=True, text=True, timeout=300
        )
    assert stopped.returncode == 0
    assert overlay.read_bytes() == before, "a start rewrote the user's overlay"


def _start(env: dict[str, str], *options: str) -> subprocess.CompletedProcess:
    return subprocess.run(
        [*ROBOTALE, "neo4j", "start", *options],
        env=env,
        capture_output=True,
        text=True,
        timeout=300,
    )


def _settings(conf: Path) -> dict[str, str]:
    pairs = (line.split("=", 1) for line in conf.read_text().splitlines() if "=" in line)
    return {key: value for key, value in pairs if not key.startswith("#")}


def _ended(pid: int) -> bool:
    try:
        state = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()[0]
    except FileNotFoundError:
        return True
    return state == "Z"


def test_an_unpinned_plugin_is_refused_naming_the_pinned_ones():
    with pytest.raises(ServerError, match=r"No plugin 'apoc-full' is pinned .*apoc-core, "):
        jars.plugin_jar("apoc-full")


def test_apoc_core_and_extended_are_pinned_at_one_version():
    pinned = {jar.artifact: jar for jar in jars.read_lock(jars.PLUGIN_LOCK_FILE)}
    assert pinned["apoc-core"].version == pinned["apoc-extended"].version
    assert pinned["apoc-core"].version.split(".")[:2] == jars.NEO4J_VERSION.split(".")[:2]
    assert all(len(jar.sha1) == 40 and jar.size > 0 for jar in pinned.values())
