"""`make demo`, shortened to two runs, ends with the dashboard answering and both logs stored."""

from __future__ import annotations

import os
import shutil
import signal
import socket
import subprocess
import time
import urllib.request
from pathlib import Path

import pandas as pd
import pytest
from patience import patience

from robotale.ekg.logs import delete_log, log_summary

REPO = Path(__file__).resolve().parent.parent
DEMO_LOGS = ("agri", "thesis")


def free_port() -> int:
    with socket.socket() as sock:
        sock.bind(("127.0.0.1", 0))
        return sock.getsockname()[1]


def wait_for_line(process: subprocess.Popen, marker: str, seconds: float) -> list[str]:
    """The lines ``process`` printed up to the one holding ``marker``."""
    lines: list[str] = []
    deadline = time.monotonic() + seconds
    while time.monotonic() < deadline:
        line = process.stdout.readline()
        if not line and process.poll() is not None:
            break
        lines.append(line)
        if marker in line:
            return lines
    pytest.fail(f"no {marker!r} from the demo; it printed:\n{''.join(lines)}")


def _as_from_a_terminal() -> None:
    # A process started in the background by a non-interactive shell inherits SIGINT ignored,
    # and Python then installs no KeyboardInterrupt: give the demo what a terminal gives it.
    signal.signal(signal.SIGINT, signal.SIG_DFL)


@pytest.fixture
def demo_logs(neo4j_driver):
    for name in DEMO_LOGS:
        delete_log(neo4j_driver, name)
    yield
    for name in DEMO_LOGS:
        delete_log(neo4j_driver, name)


@pytest.mark.slow
@pytest.mark.skipif(shutil.which("make") is None, reason="make is not installed")
def test_make_demo_serves_the_dashboard_with_the_ingested_logs(tmp_path, neo4j_driver, demo_logs):
    port = free_port()
    out = tmp_path / "demo"
    environment = os.environ | {"ROBOTALE_DEMO_RUNS": "2", "ROBOTALE_HOME": str(tmp_path)}
    process = subprocess.Popen(
        ["make", "--no-print-directory", "demo", f"DEMO_ARGS=--port {port} --out {out}"],
        cwd=REPO,
        env=environment,
        stdout=subprocess.PIPE,
        stderr=subprocess.STDOUT,
        text=True,
        start_new_session=True,
        preexec_fn=_as_from_a_terminal,
    )
    try:
        printed = "".join(wait_for_line(process, "robotale dashboard at ", 600))
        page = urllib.request.urlopen(f"http://127.0.0.1:{port}/logs", timeout=patience(30)).read()
        for name in DEMO_LOGS:
            assert f">{name}<".encode() in page, name

        # the graph holds the events of the CSV the demo prepared from its two runs
        prepared = pd.read_csv(out / "agri.csv")
        assert sorted(prepared["case"].unique()) == ["run_0001", "run_0002"]
        counts = log_summary(neo4j_driver, "agri")["counts"]
        assert counts["events"] == len(prepared) and counts["cases"] == 2
        assert f"Log 'agri': {len(prepared):,} events" in printed
        assert log_summary(neo4j_driver, "thesis")["counts"]["events"] == 3648

        # Ctrl-C in a terminal signals the whole foreground group: make and the demo
        os.killpg(process.pid, signal.SIGINT)
        rest, _ = process.communicate(timeout=patience(60))
        assert "Dashboard stopped" in rest
    finally:
        if process.poll() is None:
            os.killpg(process.pid, signal.SIGKILL)
            process.wait()


def test_a_server_that_is_down_stops_the_demo_before_the_work(tmp_path, monkeypatch, capsys):
    from robotale.cli import main

    uri = f"bolt://127.0.0.1:{free_port()}"
    monkeypatch.setenv("NEO4J_URI", uri)
    assert main(["demo", "--no-serve", "--out", str(tmp_path / "demo")]) == 1
    error = capsys.readouterr().err.strip()
    assert error == (
        f"robotale: Neo4j is not reachable at {uri} (NEO4J_URI): start that server, or unset "
        "NEO4J_URI and run `robotale neo4j start`."
    )
    assert not (tmp_path / "demo").exists()


def test_a_port_in_use_stops_the_demo_before_the_work(tmp_path, capsys):
    from robotale.cli import main

    with socket.socket() as taken:
        taken.bind(("127.0.0.1", 0))
        taken.listen()
        port = taken.getsockname()[1]
        assert main(["demo", "--port", str(port), "--out", str(tmp_path / "demo")]) == 1
    error = capsys.readouterr().err.strip()
    assert error == f"robotale: Port {port} on 127.0.0.1 is in use: choose another with --port."
    assert not (tmp_path / "demo").exists()
