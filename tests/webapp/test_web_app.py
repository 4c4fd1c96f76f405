"""The app itself: Neo4j down, errors as one sentence, assets served locally, `robotale serve`."""

from __future__ import annotations

import json
import re
import socket
import subprocess
import sys
import time
import urllib.error
import urllib.request
from pathlib import Path

import pytest
from patience import patience

from robotale.neo4j_server.server import free_port
from robotale.webapp import create_app
from robotale.webapp.serve import Dashboard

REPO = Path(__file__).resolve().parents[2]
STATIC = REPO / "robotale" / "webapp" / "static"


@pytest.fixture
def neo4j_down(monkeypatch, web_settings):
    """An app whose Neo4j is a port nobody listens on."""
    monkeypatch.setenv("NEO4J_URI", f"bolt://127.0.0.1:{free_port()}")
    return create_app(web_settings)


def test_neo4j_down_shows_how_to_start_it(neo4j_down):
    client = neo4j_down.test_client()
    response = client.get("/cypher")
    assert response.status_code == 503
    page = response.get_data(as_text=True)
    assert "Neo4j is not available" in page
    assert "Neo4j is not reachable at bolt://127.0.0.1:" in page
    assert "robotale neo4j start" in page
    api = client.get("/api/logs")
    assert api.status_code == 503 and "robotale neo4j start" in api.json["hint"]


def test_neo4j_down_for_json_endpoints_is_json(neo4j_down):
    client = neo4j_down.test_client()
    page = client.get("/vendor/plotly.min.js")  # needs no database
    assert page.status_code == 200
    token = re.search(rb'csrf-token" content="([^"]+)"', client.get("/cypher").data).group(1)
    response = client.post(
        "/api/cypher", json={"query": "RETURN 1"}, headers={"X-CSRFToken": token.decode()}
    )
    assert response.status_code == 503
    assert "robotale neo4j start" in response.json["hint"]


def test_unknown_pages_are_a_plain_404(client):
    response = client.get("/no/such/page")
    assert response.status_code == 404 and "Not Found" in response.get_data(as_text=True)
    assert client.get("/api/no/such").json["error"]


def test_vendored_libraries_match_their_manifest():
    result = subprocess.run(
        [sys.executable, str(REPO / "scripts" / "vendor_js.py"), "--check"],
        capture_output=True,
        text=True,
    )
    assert result.returncode == 0, result.stderr
    manifest = json.loads((STATIC / "vendor" / "vendor.json").read_text())
    assert {"cytoscape", "cytoscape-dagre", "bpmn-js"} <= set(manifest)
    assert all(entry["integrity"].startswith("sha512-") for entry in manifest.values())


def test_vendor_check_notices_a_changed_file(tmp_path, monkeypatch):
    sys.path.insert(0, str(REPO / "scripts"))
    try:
        import vendor_js
    finally:
        sys.path.pop(0)
    copy = tmp_path / "vendor"
    import shutil

    shutil.copytree(STATIC / "vendor", copy)
    monkeypatch.setattr(vendor_js, "VENDOR", copy)
    monkeypatch.setattr(vendor_js, "MANIFEST", copy / "vendor.json")
    assert vendor_js.check() == []
    (copy / "cytoscape" / "cytoscape.min.js").write_text("// tampered")
    assert vendor_js.check() == ["cytoscape/cytoscape.min.js is missing or changed"]


def test_templates_load_scripts_only_from_the_app():
    for template in (REPO / "robotale" / "webapp" / "templates").glob("*.html"):
        text = template.read_text()
        assert not re.search(r"(src|href)=\"(https?:)?//", text), template.name


def test_plotly_js_comes_from_the_python_package(client):
    from plotly.offline import get_plotlyjs

    response = client.get("/vendor/plotly.min.js")
    assert response.status_code == 200 and response.mimetype == "text/javascript"
    assert response.get_data(as_text=True) == get_plotlyjs()
    again = client.get("/vendor/plotly.min.js", headers={"If-None-Match": response.headers["ETag"]})
    assert again.status_code == 304


def test_dashboard_binds_to_loopback_by_default(app):
    with Dashboard(app, port=0) as running:
        assert running.server.host == "127.0.0.1"
        assert re.fullmatch(r"http://127\.0\.0\.1:\d+", running.url)
        with urllib.request.urlopen(running.url + "/cypher", timeout=10) as response:
            assert response.status == 200


def test_port_in_use_is_one_sentence(app):
    from robotale.errors import ServerError

    with socket.socket() as taken:
        taken.bind(("127.0.0.1", 0))
        taken.listen()
        port = taken.getsockname()[1]
        with pytest.raises(ServerError, match=f"Port {port} on 127.0.0.1 is in use"):
            Dashboard(app, port=port)


@pytest.mark.slow
def test_robotale_serve_answers(neo4j_server, tmp_path):
    port = free_port()
    env_home = {"ROBOTALE_UPLOAD_DIR": str(tmp_path / "uploads")}
    import os

    process = subprocess.Popen(
        [sys.executable, "-m", "robotale", "serve", "--port", str(port), "--log", "agri runs"],
        env={**os.environ, **env_home},
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
    )
    try:
        body = _wait_for(f"http://127.0.0.1:{port}/cypher", process)
        assert "Cypher console" in body
    finally:
        process.terminate()
        _, stderr = process.communicate(timeout=patience(20))
    assert f"robotale dashboard at http://127.0.0.1:{port}/discover?log=agri+runs" in stderr
    # NEO4J_URI names the server: the console would log in as robotale's own user
    assert "ROBOTALE_CONSOLE_USER and ROBOTALE_CONSOLE_PASSWORD" in stderr


def _wait_for(url: str, process: subprocess.Popen, timeout: float = 60) -> str:
    timeout = patience(timeout)
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        assert process.poll() is None, process.communicate()[1]
        try:
            with urllib.request.urlopen(url, timeout=5) as response:
                return response.read().decode()
        except OSError:  # not listening yet, or too busy to answer within 5 s
            time.sleep(0.3)
    raise AssertionError(f"{url} did not answer within {timeout} s")


def test_settings_come_from_the_environment(monkeypatch, tmp_path):
    from robotale.errors import InputError
    from robotale.webapp.settings import WebSettings

    monkeypatch.setenv("ROBOTALE_HOME", str(tmp_path))
    monkeypatch.delenv("ROBOTALE_UPLOAD_DIR", raising=False)
    monkeypatch.setenv("ROBOTALE_UPLOAD_LIMIT_MB", "20")
    settings = WebSettings.from_env()
    assert settings.upload_dir == tmp_path / "uploads" and settings.upload_limit_mb == 20
    assert len(settings.secret_key) == 64
    monkeypatch.setenv("ROBOTALE_UPLOAD_LIMIT_MB", "lots")
    with pytest.raises(InputError, match="ROBOTALE_UPLOAD_LIMIT_MB is 'lots'"):
        WebSettings.from_env()
