"""The local Neo4j server, its jars and the connection, against real servers and files."""

from __future__ import annotations

import hashlib
import http.server
import json
import os
import socket
import stat
import subprocess
import sys
import threading
import urllib.request
from concurrent.futures import ThreadPoolExecutor
from functools import partial
from pathlib import Path
from typing import ClassVar

import pytest

from robotale.ekg import connection
from robotale.errors import ServerError
from robotale.neo4j_server import jars
from robotale.neo4j_server.server import (
    LocalServer,
    PortInUse,
    ServerOptions,
    free_port,
    java_executable,
)

ROBOTALE = [sys.executable, "-m", "robotale"]


def test_session_server_is_neo4j_5_26_community(neo4j_driver):
    info = connection.server_version(neo4j_driver)
    assert info["name"] == "Neo4j Kernel" and info["version"].startswith("5.")
    records, _, _ = neo4j_driver.execute_query("RETURN 40 + 2 AS answer")
    assert records[0]["answer"] == 42


def test_lock_pins_server_browser_and_bolt_jars():
    pinned = {f"{j.group}:{j.artifact}": j for j in jars.read_lock()}
    assert pinned["org.neo4j:neo4j"].version == jars.NEO4J_VERSION
    assert pinned["org.neo4j.app:neo4j-server"].version == jars.NEO4J_VERSION
    assert pinned["org.neo4j.client:neo4j-browser"].version == jars.BROWSER_VERSION
    assert "org.neo4j:neo4j-bolt" in pinned
    assert all(len(j.sha1) == 40 and j.size > 0 for j in pinned.values())
    assert len(pinned) > 150


def test_cached_jars_are_used_without_touching_the_network():
    # Once the cache is complete (usually already, from the session's server), a repository
    # nobody serves must not matter, and every jar on disk must match its pinned sha1.
    jars.ensure_jars()
    lib = jars.ensure_jars(repository="http://127.0.0.1:9")
    pinned = jars.read_lock()
    assert sorted(p.name for p in lib.glob("*.jar")) == sorted(j.filename for j in pinned)
    sample = pinned[0]
    assert hashlib.sha1((lib / sample.filename).read_bytes()).hexdigest() == sample.sha1


# -- provisioning from a real (local) Maven-layout HTTP repository ---------------------------


@pytest.fixture
def repository(tmp_path):
    """Two jars in Maven's layout served over HTTP, and a lock that pins them."""
    root = tmp_path / "repo"
    pinned = []
    for artifact, payload in (("alpha", b"A" * 5000), ("beta", b"B" * 7000)):
        jar = jars.Jar(
            "org.example", artifact, "1.0", "", hashlib.sha1(payload).hexdigest(), len(payload)
        )
        target = root / "org" / "example" / artifact / "1.0" / jar.filename
        target.parent.mkdir(parents=True)
        target.write_bytes(payload)
        pinned.append(jar)
    lock = tmp_path / "test.lock"
    lock.write_text("# test\n" + "\n".join(j.lock_line() for j in pinned) + "\n")
    handler = partial(QuietHandler, directory=str(root))
    server = http.server.ThreadingHTTPServer(("127.0.0.1", 0), handler)
    thread = threading.Thread(target=server.serve_forever, daemon=True)
    thread.start()
    yield f"http://127.0.0.1:{server.server_address[1]}", lock, root, pinned
    server.shutdown()


class QuietHandler(http.server.SimpleHTTPRequestHandler):
    requests: ClassVar[list[str]] = []

    def log_message(self, *args):
        QuietHandler.requests.append(self.path)


def test_jars_download_verify_and_a_second_call_stays_offline(repository, tmp_path):
    url, lock, _, pinned = repository
    lib = tmp_path / "cache" / "lib"
    QuietHandler.requests.clear()
    assert jars.ensure_jars(lib, url, lock) == lib
    for jar in pinned:
        assert hashlib.sha1((lib / jar.filename).read_bytes()).hexdigest() == jar.sha1
    assert len(QuietHandler.requests) == 2
    jars.ensure_jars(lib, url, lock)
    assert len(QuietHandler.requests) == 2, "the second call went to the network"


def test_concurrent_provisioning_downloads_each_jar_once(repository, tmp_path):
    url, lock, _, pinned = repository
    lib = tmp_path / "cache" / "lib"
    QuietHandler.requests.clear()
    with ThreadPoolExecutor(4) as pool:
        done = list(pool.map(lambda _: jars.ensure_jars(lib, url, lock), range(4)))
    assert done == [lib] * 4
    assert sorted(QuietHandler.requests) == sorted("/" + j.url("").lstrip("/") for j in pinned)
    assert sorted(p.name for p in lib.iterdir() if p.suffix == ".jar") == sorted(
        j.filename for j in pinned
    )


def test_a_jar_with_the_wrong_sha1_is_refused_and_not_kept(repository, tmp_path):
    url, lock, root, pinned = repository
    tampered = root / "org" / "example" / "beta" / "1.0" / pinned[1].filename
    tampered.write_bytes(b"X" * pinned[1].size)
    lib = tmp_path / "cache" / "lib"
    with pytest.raises(ServerError, match=r"beta-1\.0\.jar has sha1 .* not the pinned"):
        jars.ensure_jars(lib, url, lock)
    assert not (lib / pinned[1].filename).exists()
    assert not list(lib.glob(".*.part")), "a partial download was left behind"
    assert not (lib / ".complete").exists()


def test_an_unreachable_repository_names_the_jar(repository, tmp_path):
    _, lock, _, _ = repository
    with pytest.raises(ServerError, match=r"Could not download the Neo4j jar .*alpha-1\.0\.jar"):
        jars.ensure_jars(tmp_path / "lib", f"http://127.0.0.1:{free_port()}", lock)


# -- connection errors -----------------------------------------------------------------------


def test_local_server_down_says_how_to_start_it(tmp_path, monkeypatch):
    monkeypatch.delenv("NEO4J_URI", raising=False)
    monkeypatch.setenv("ROBOTALE_HOME", str(tmp_path))
    monkeypatch.setenv("ROBOTALE_NEO4J_BOLT_PORT", str(free_port()))
    with pytest.raises(ServerError) as error:
        connection.connect()
    assert "is not running" in str(error.value)
    assert "robotale neo4j start" in str(error.value)
    assert "NEO4J_URI" in str(error.value)


def test_neo4j_uri_down_names_the_variable(monkeypatch):
    uri = f"bolt://127.0.0.1:{free_port()}"
    monkeypatch.setenv("NEO4J_URI", uri)
    with pytest.raises(ServerError, match=rf"not reachable at {uri} \(NEO4J_URI\)"):
        connection.connect()


def test_wrong_password_is_one_sentence(neo4j_server, monkeypatch):
    monkeypatch.setenv("NEO4J_PASSWORD", "not-the-password")
    with pytest.raises(ServerError, match="refused user 'neo4j': set NEO4J_USER and"):
        connection.connect()


def test_cli_reports_server_down_in_one_line(tmp_path):
    env = {**os.environ, "NEO4J_URI": f"bolt://127.0.0.1:{free_port()}"}
    result = subprocess.run([*ROBOTALE, "neo4j", "status"], env=env, capture_output=True, text=True)
    assert result.returncode == 3
    assert "does not answer" in result.stdout


def test_start_refuses_a_port_in_use(tmp_path):
    with socket.socket() as taken:
        taken.bind(("127.0.0.1", 0))
        taken.listen()
        port = taken.getsockname()[1]
        server = LocalServer(tmp_path)
        with pytest.raises(PortInUse, match=rf"bolt port {port} on 127\.0\.0\.1 is in use"):
            server.start(ServerOptions(bolt_port=port, http_port=free_port()))
    assert server.running() is None


def test_a_password_that_looks_like_an_option_is_set(tmp_path, monkeypatch):
    monkeypatch.setenv("NEO4J_PASSWORD", "-looks-like-an-option")
    server = LocalServer(tmp_path)
    server._write_config(ServerOptions(free_port(), free_port()))
    server._ensure_password(java_executable(), jars.ensure_jars())
    assert server.password() == "-looks-like-an-option"
    assert (server.home / "data" / "dbms" / "auth.ini").read_text().startswith("neo4j:")


def test_a_stale_record_is_not_a_running_server(tmp_path):
    server = LocalServer(tmp_path)
    server.home.mkdir(parents=True)
    # Our own pid is alive but is no Neo4j of this home.
    server.state_file.write_text(json.dumps({"pid": os.getpid(), "bolt_port": 1, "http_port": 2}))
    assert server.running() is None
    assert not server.state_file.exists()


# -- the whole life cycle through the command line -------------------------------------------


@pytest.mark.slow
def test_cli_start_status_stop(tmp_path, neo4j_server):
    # neo4j_server first: it provisions the jar cache this second server shares.
    env = {k: v for k, v in os.environ.items() if not k.startswith("NEO4J_")}
    env |= {
        "ROBOTALE_HOME": str(tmp_path),
        "ROBOTALE_CACHE": str(jars.server_dir().parent),
        "ROBOTALE_NEO4J_HEAP": "512m",
        "ROBOTALE_NEO4J_PAGECACHE": "64m",
    }
    bolt, http_port = free_port(), free_port()
    run = partial(subprocess.run, env=env, capture_output=True, text=True, timeout=300)
    try:
        started = run(
            [*ROBOTALE, "neo4j", "start", "--bolt-port", str(bolt), "--http-port", str(http_port)]
        )
        assert started.returncode == 0, started.stderr
        assert f"is running at bolt://127.0.0.1:{bolt}" in started.stdout
        server = LocalServer(tmp_path)
        running = server.running()
        assert running is not None and running.bolt_port == bolt
        assert stat.S_IMODE(server.password_file.stat().st_mode) == 0o600

        status = run([*ROBOTALE, "neo4j", "status"])
        assert status.returncode == 0 and "answers" in status.stdout
        where = connection.Settings(running.bolt_uri, "neo4j", server.password() or "", True)
        with connection.connect(where) as driver:
            assert connection.server_version(driver) == {
                "name": "Neo4j Kernel",
                "version": jars.NEO4J_VERSION,
                "edition": "community",
            }
        assert _listening_addresses(bolt) == {"127.0.0.1"}
        assert _listening_addresses(http_port) == {"127.0.0.1"}
        with urllib.request.urlopen(f"http://127.0.0.1:{http_port}/browser/") as page:
            assert "<title>Neo4j Browser</title>" in page.read().decode()

        again = run([*ROBOTALE, "neo4j", "start", "--bolt-port", str(bolt)])
        assert "was already running" in again.stdout and f"pid {running.pid}" in again.stdout
    finally:
        stopped = run([*ROBOTALE, "neo4j", "stop"])
    assert stopped.returncode == 0 and "Stopped the local Neo4j" in stopped.stdout
    assert _ended(running.pid)
    assert "Stopped." in server.log_file.read_text()  # a clean shutdown, not a kill
    after = run([*ROBOTALE, "neo4j", "status"])
    assert after.returncode == 3 and "not running" in after.stdout


def _ended(pid: int) -> bool:
    """True when ``pid`` has exited (it may linger as a zombie until init collects it)."""
    try:
        stat_line = Path(f"/proc/{pid}/stat").read_text()
    except FileNotFoundError:
        return True
    return stat_line.rsplit(")", 1)[1].split()[0] == "Z"


def _listening_addresses(port: int) -> set[str]:
    """The local addresses that listen on ``port`` (from /proc/net/tcp and tcp6)."""
    found = set()
    for table in ("/proc/net/tcp", "/proc/net/tcp6"):
        for line in Path(table).read_text().splitlines()[1:]:
            local, state = line.split()[1], line.split()[3]
            address, hex_port = local.split(":")
            if state == "0A" and int(hex_port, 16) == port:  # 0A = LISTEN
                found.add(_decode_address(address))
    return found


def _decode_address(hex_address: str) -> str:
    raw = bytes.fromhex(hex_address)
    if len(raw) == 4:
        return socket.inet_ntop(socket.AF_INET, raw[::-1])
    words = b"".join(raw[i : i + 4][::-1] for i in range(0, 16, 4))
    # Java listens on IPv4 addresses through IPv4-mapped IPv6 sockets.
    return socket.inet_ntop(socket.AF_INET6, words).removeprefix("::ffff:")
