"""A local Neo4j killed with SIGKILL in the middle of an ingest, then started again: what
`neo4j status`, `logs list` and `logs delete` say is true, and the delete restores the counts.
Also: a stopped server whose port something else answers on is not talked to."""

from __future__ import annotations

import json
import os
import re
import signal
import socket
import subprocess
import sys
import time
from collections.abc import Iterator
from dataclasses import dataclass
from functools import partial
from pathlib import Path

import pandas as pd
import pytest
from neo4j import GraphDatabase
from patience import patience

from robotale.neo4j_server import jars
from robotale.neo4j_server import server as server_module
from robotale.neo4j_server.server import CRASHED, LocalServer, PortInUse, free_port

ROBOTALE = [sys.executable, "-m", "robotale"]
# Six batches of events written two at a time, then the edges between batches and the
# classes: the kill, sent once the first batch is stored, lands with seconds of writing left.
# Below the bulk build's threshold, so the build is the online one whatever else is connected.
EVENTS = 30_000


def _big_log(path: Path) -> Path:
    """A log long enough that the kill lands while it is being written."""
    times = pd.date_range("2024-01-01", periods=EVENTS, freq="s", tz="UTC")
    pd.DataFrame(
        {
            "case": [f"c{i // 50}" for i in range(EVENTS)],
            "activity": [f"a{i % 7}" for i in range(EVENTS)],
            "timestamp": times.strftime("%Y-%m-%dT%H:%M:%SZ"),
            "robot": [f"r{i % 5}" for i in range(EVENTS)],
        }
    ).to_csv(path, index=False)
    return path


def _count(driver, query: str, **params) -> int:
    records, _, _ = driver.execute_query(query, params)
    return int(records[0][0])


def _wait_for_events(driver, name: str, ingest: subprocess.Popen) -> None:
    deadline = time.monotonic() + 300
    query = "MATCH (e:Event) WHERE e.log = $name AND e.id IS NOT NULL RETURN count(e)"
    while _count(driver, query, name=name) == 0:
        assert ingest.poll() is None, ingest.communicate()
        assert time.monotonic() < deadline
        time.sleep(0.2)


@pytest.mark.slow
def test_sigkill_mid_ingest_then_start_status_list_delete(tmp_path, env):
    run = partial(subprocess.run, env=env, capture_output=True, text=True, timeout=300)
    bolt, http_port = free_port(), free_port()
    started = run(
        [*ROBOTALE, "neo4j", "start", "--bolt-port", str(bolt), "--http-port", str(http_port)]
    )
    assert started.returncode == 0, started.stderr
    server = LocalServer(tmp_path / "home")
    auth = ("neo4j", server.password() or "")
    uri = f"bolt://127.0.0.1:{bolt}"
    try:
        csv = _big_log(tmp_path / "big.csv")
        ingest = subprocess.Popen(
            [*ROBOTALE, "ingest", str(csv), "--log", "big"],
            env=env,
            stdout=subprocess.PIPE,
            stderr=subprocess.PIPE,
            text=True,
        )
        with GraphDatabase.driver(uri, auth=auth) as driver:
            _wait_for_events(driver, "big", ingest)
        pid = server.running().pid
        os.kill(pid, signal.SIGKILL)
        _, error = ingest.communicate(timeout=300)
        assert ingest.returncode == 1
        assert len(error.strip().splitlines()) == 1 and "robotale logs delete" in error

        status = run([*ROBOTALE, "neo4j", "status"])
        assert status.returncode == 1
        assert f"crashed): its process {pid} is gone" in status.stdout
        refused = run([*ROBOTALE, "logs", "list"])
        assert refused.returncode == 1
        assert f"(pid {pid}, bolt port {bolt}) has crashed" in refused.stderr

        again = run([*ROBOTALE, "neo4j", "start"])  # no ports given: the recorded ones
        assert again.returncode == 0, again.stderr
        assert f"is running at {uri}" in again.stdout
        assert run([*ROBOTALE, "neo4j", "status"]).returncode == 0

        with GraphDatabase.driver(uri, auth=auth) as driver:
            stored = _count(driver, "MATCH (e:Event {log: 'big'}) RETURN count(e)")
            assert 0 < stored < EVENTS
            listed = run([*ROBOTALE, "logs", "list"])
            assert listed.returncode == 0, listed.stderr
            assert f"big  [failed]  {stored:,} events" in listed.stdout
            assert "remove it with `robotale logs delete big`" in listed.stdout
            retry = run([*ROBOTALE, "ingest", str(csv), "--log", "big"])
            assert retry.returncode == 1
            assert retry.stderr.strip() == (
                f"robotale: The log 'big' in Neo4j is what a failed ingest left ({stored:,} "
                "events): remove it with `robotale logs delete big`, or ingest again with "
                "--replace to rebuild it."
            )
            deleted = run([*ROBOTALE, "logs", "delete", "big"])
            assert deleted.returncode == 0, deleted.stderr
            # The database was empty before the ingest: nothing is left, not even its lock.
            assert _count(driver, "MATCH (n) RETURN count(n)") == 0
    finally:
        run([*ROBOTALE, "neo4j", "stop"])


def _crashed_record(server: LocalServer) -> tuple[int, int]:
    """Record a server of ``server``'s home that crashed: its process is gone, it was never
    stopped. Returns its bolt and http ports."""
    gone = subprocess.run(
        [sys.executable, "-c", "import os; print(os.getpid())"],
        capture_output=True,
        text=True,
        check=True,
    )
    bolt, http_port = free_port(), free_port()
    server.home.mkdir(parents=True, exist_ok=True)
    record = {"pid": int(gone.stdout), "bolt_port": bolt, "http_port": http_port}
    server.ports_file.write_text(json.dumps(record | {"stopped": False}))
    assert server.condition().condition == CRASHED
    return bolt, http_port


def test_start_after_a_crash_waits_for_its_port_and_says_why_it_gave_up(tmp_path, monkeypatch):
    server = LocalServer(tmp_path)
    bolt, _ = _crashed_record(server)
    lines: list[str] = []
    # Bound but not listening, as a dead server's socket the kernel has not let go of yet:
    # the port is not free, and nothing answers there.
    with socket.socket() as lingering:
        lingering.bind(("127.0.0.1", bolt))
        monkeypatch.setattr(server_module, "PORT_WAIT", 3.0)
        with pytest.raises(PortInUse) as refused:
            server.start(progress=lines.append)
    assert lines, "no progress line while waiting"
    for line in lines:
        assert re.fullmatch(
            rf"Waiting for the bolt port {bolt} to be free \(\d+ s left\) \.\.\.", line
        )
    message = str(refused.value)
    assert message.startswith(
        f"The bolt port {bolt} on 127.0.0.1 of the last local Neo4j was still not free after 3 s"
    )
    assert "\n" not in message and "--bolt-port" in message
    assert server.running() is None


@dataclass(frozen=True)
class Restart:
    """What `robotale neo4j start` said when it started the server of a crashed record whose
    bolt port another process held until the start had said it waits, then `status` and
    `stop` of that server."""

    env: dict[str, str]
    bolt: int
    waiting: str
    returncode: int | None
    out: str
    error: str
    status: subprocess.CompletedProcess
    stopped: subprocess.CompletedProcess


@pytest.fixture(scope="module")
def restarted_after_a_crash(tmp_path_factory, neo4j_server) -> Iterator[Restart]:
    """One server for two tests: started after a crash (the first test), then stopped, which
    leaves the stopped server's ports for the second. neo4j_server first: it provisions the
    jar cache this server shares."""
    root = tmp_path_factory.mktemp("crashed")
    env = {k: v for k, v in os.environ.items() if not k.startswith("NEO4J_")} | {
        "ROBOTALE_HOME": str(root / "home"),
        "ROBOTALE_CACHE": str(jars.server_dir().parent),
        "ROBOTALE_NEO4J_HEAP": "512m",
        "ROBOTALE_NEO4J_PAGECACHE": "64m",
    }
    bolt, _ = _crashed_record(LocalServer(root / "home"))
    # Holds the port (bound, not listening) until its stdin closes.
    holder = subprocess.Popen(
        [
            sys.executable,
            "-c",
            "import socket, sys\n"
            f"s = socket.socket(); s.bind(('127.0.0.1', {bolt})); print('held', flush=True)\n"
            "sys.stdin.read()",
        ],
        stdin=subprocess.PIPE,
        stdout=subprocess.PIPE,
        text=True,
    )
    assert holder.stdout.readline().strip() == "held"
    start = subprocess.Popen(
        [*ROBOTALE, "neo4j", "start"],
        env=env,
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
    )
    run = partial(subprocess.run, env=env, capture_output=True, text=True, timeout=300)
    try:
        waiting = start.stderr.readline()
        holder.stdin.close()  # the port is let go of while start waits for it
        out, error = start.communicate(timeout=300)
        status = run([*ROBOTALE, "neo4j", "status"], timeout=patience(60))
    finally:
        if holder.stdin and not holder.stdin.closed:
            holder.stdin.close()
        holder.wait(timeout=patience(30))
        if start.poll() is None:
            start.kill()
            start.wait()
        stopped = run([*ROBOTALE, "neo4j", "stop"])
    yield Restart(env, bolt, waiting, start.returncode, out, error, status, stopped)
    run([*ROBOTALE, "neo4j", "stop"])


@pytest.mark.slow
def test_start_after_a_crash_waits_with_a_progress_line_until_its_port_is_free(
    restarted_after_a_crash,
):
    restart = restarted_after_a_crash
    assert f"Waiting for the bolt port {restart.bolt} to be free" in restart.waiting, restart
    assert restart.returncode == 0, restart.error
    assert "The local Neo4j had crashed; starting it again." in restart.out
    assert f"is running at bolt://127.0.0.1:{restart.bolt}" in restart.out
    assert restart.status.returncode == 0, restart.status.stdout


@pytest.mark.slow
def test_a_stopped_servers_port_answered_by_something_else(restarted_after_a_crash):
    restart = restarted_after_a_crash
    run = partial(subprocess.run, env=restart.env, capture_output=True, text=True, timeout=300)
    assert restart.stopped.returncode == 0, restart.stopped.stderr
    bolt = restart.bolt
    assert run([*ROBOTALE, "neo4j", "status"]).returncode == 3
    with socket.socket() as impostor:
        impostor.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
        impostor.bind(("127.0.0.1", bolt))
        impostor.listen()
        status = run([*ROBOTALE, "neo4j", "status"])
        assert status.returncode == 4 and "something else answers" in status.stdout
        listed = run([*ROBOTALE, "logs", "list"])
        assert listed.returncode == 1
        assert f"something else answers on its bolt port {bolt}" in listed.stderr
        again = run([*ROBOTALE, "neo4j", "start"])
        assert again.returncode == 1
        # the holder is this test's own process, named when /proc shows it
        holder = (
            rf"port {bolt} on 127\.0\.0\.1 is held by (something else|\S+ \(pid {os.getpid()}\))"
        )
        assert re.search(holder, again.stderr), again.stderr
