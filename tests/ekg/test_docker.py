"""docker-compose.yml and the Dockerfile, checked without a Docker engine."""

from __future__ import annotations

import fnmatch
import http.client
import json
import os
import re
import shutil
import subprocess
import sys
import time
from pathlib import Path

import yaml

from robotale.neo4j_server import jars

REPO = Path(__file__).resolve().parents[2]


def compose_config(**env: str) -> dict:
    assert shutil.which("docker-compose"), "install the Debian package docker-compose"
    environment = {k: v for k, v in os.environ.items() if not k.startswith("NEO4J_")} | env
    result = subprocess.run(
        ["docker-compose", "-f", str(REPO / "docker-compose.yml"), "config"],
        capture_output=True,
        text=True,
        env=environment,
        cwd=REPO,
    )
    assert result.returncode == 0, result.stderr
    return yaml.safe_load(result.stdout)


def test_compose_runs_neo4j_and_the_dashboard_against_it():
    config = compose_config(NEO4J_PASSWORD="a-secret-1")
    neo4j, dashboard = config["services"]["neo4j"], config["services"]["dashboard"]
    assert neo4j["image"] == f"neo4j:{jars.RELEASES['2026.08'].version}-community"
    lts = compose_config(NEO4J_PASSWORD="a-secret-1", NEO4J_VERSION="5.26")
    assert lts["services"]["neo4j"]["image"] == "neo4j:5.26-community"
    assert neo4j["environment"]["NEO4J_AUTH"] == "neo4j/a-secret-1"
    assert "neo4j-data:/data:rw" in neo4j["volumes"]
    assert "cypher-shell" in " ".join(neo4j["healthcheck"]["test"])
    assert dashboard["environment"] == {
        "NEO4J_URI": "bolt://neo4j:7687",
        "NEO4J_USER": "neo4j",
        "NEO4J_PASSWORD": "a-secret-1",
        "ROBOTALE_ALLOWED_HOSTS": "",
    }
    assert dashboard["depends_on"] == {"neo4j": {"condition": "service_healthy"}}
    assert "command" not in dashboard, "the image's production server serves the dashboard"
    assert Path(dashboard["build"]["context"]) == REPO
    ports = neo4j["ports"] + dashboard["ports"]
    assert all(str(port).startswith("127.0.0.1:") for port in ports), "this machine only"


def test_compose_has_a_local_default_password():
    config = compose_config()
    assert config["services"]["neo4j"]["environment"]["NEO4J_AUTH"] == "neo4j/robotale-local"
    dashboard = config["services"]["dashboard"]["environment"]
    assert dashboard["NEO4J_PASSWORD"] == "robotale-local"


def test_dockerfile_copies_only_what_exists_and_is_not_ignored():
    dockerfile = (REPO / "Dockerfile").read_text()
    ignored = [
        line.strip()
        for line in (REPO / ".dockerignore").read_text().splitlines()
        if line.strip() and not line.startswith("#")
    ]
    sources = []
    for line in dockerfile.splitlines():
        if line.startswith("COPY") and "--from=" not in line:
            sources += [s for s in line.split()[1:-1] if not s.startswith("--")]
    assert {"robotale", "cypher", "setup.py", "pyproject.toml", "examples"} <= set(sources)
    for source in sources:
        assert (REPO / source).exists(), source
        assert not any(fnmatch.fnmatch(source, pattern) for pattern in ignored), source
    command = re.search(r"^CMD \[(.*)\]$", dockerfile, re.M).group(1)
    # a production WSGI server, not werkzeug's development one, serving the app factory
    words = command.replace('"', "").split(", ")
    assert words[0] == "waitress-serve" and words[-1] == "robotale.webapp:create_app"
    assert "--call" in words and "--listen=0.0.0.0:5000" in words


def _image_command() -> list[str]:
    dockerfile = (REPO / "Dockerfile").read_text()
    return json.loads(re.search(r"^CMD (\[.*\])$", dockerfile, re.M).group(1))


def _get(port: int, path: str, host: str) -> http.client.HTTPResponse:
    connection = http.client.HTTPConnection("127.0.0.1", port, timeout=30)
    connection.request("GET", path, headers={"Host": host})
    response = connection.getresponse()
    response.read()
    connection.close()
    return response


def test_the_images_command_serves_the_dashboard_with_waitress(tmp_path):
    from robotale.neo4j_server.server import free_port

    port = free_port()
    command = [
        f"--listen=127.0.0.1:{port}" if word.startswith("--listen=") else word
        for word in _image_command()
    ]
    command[0] = str(Path(sys.executable).with_name(command[0]))  # the venv's waitress-serve
    environment = {k: v for k, v in os.environ.items() if not k.startswith("NEO4J_")} | {
        "ROBOTALE_HOME": str(tmp_path),
        "ROBOTALE_ALLOWED_HOSTS": "dash.example",
    }
    served = subprocess.Popen(command, env=environment, stderr=subprocess.PIPE, text=True)
    try:
        deadline = time.monotonic() + 120
        while True:
            try:
                response = _get(port, "/static/js/common.js", f"127.0.0.1:{port}")
                break
            except OSError:
                assert served.poll() is None, served.communicate()[1]
                assert time.monotonic() < deadline, "waitress did not answer"
                time.sleep(0.5)
        assert response.status == 200
        assert response.getheader("Server") == "waitress"  # not werkzeug's development server
        assert _get(port, "/static/js/common.js", "dash.example").status == 200
        refused = _get(port, "/static/js/common.js", "attacker.example")
        assert refused.status == 403
        page = _get(port, "/cypher", f"localhost:{port}")
        assert "script-src 'self'" in page.getheader("Content-Security-Policy")
        assert page.getheader("X-Frame-Options") == "DENY"
    finally:
        served.terminate()
        served.wait(timeout=30)
