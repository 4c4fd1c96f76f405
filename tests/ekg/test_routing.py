"""Every command that talks to Neo4j, through a ``neo4j://`` URI: the routing driver a cluster
or Aura needs, here against the session's single server (which answers routing requests with
itself). Each answer is checked against the same command through ``bolt://``."""

from __future__ import annotations

import pandas as pd
import pytest

from robotale.cli import main
from robotale.ekg.connection import settings


@pytest.fixture
def uris(neo4j_server, monkeypatch) -> dict[str, str]:
    """The session's server as a direct (``bolt``) and a routed (``neo4j``) URI."""
    bolt = settings().uri
    assert bolt.startswith("bolt://")
    return {"bolt": bolt, "neo4j": "neo4j://" + bolt.removeprefix("bolt://")}


def through(scheme: str, uris, monkeypatch, capsys, *args: str) -> tuple[int, str]:
    """The command's exit status and output with NEO4J_URI on ``scheme``."""
    monkeypatch.setenv("NEO4J_URI", uris[scheme])
    code = main(list(args))
    return code, capsys.readouterr().out


def test_every_command_works_through_a_routing_uri(
    tmp_path, uris, monkeypatch, capsys, log_name, thesis_csv
):
    def both(*args: str) -> str:
        routed = through("neo4j", uris, monkeypatch, capsys, *args)
        direct = through("bolt", uris, monkeypatch, capsys, *args)
        assert routed[0] == direct[0] == 0
        assert routed[1] == direct[1].replace(uris["bolt"], uris["neo4j"])
        return routed[1]

    assert uris["neo4j"] in both("neo4j", "status")
    code, out = through(
        "neo4j", uris, monkeypatch, capsys, "ingest", str(thesis_csv), "--log", log_name,
        "--entities", "robot", "--aggregate", "activity,robot",
    )  # fmt: skip
    events = len(pd.read_csv(thesis_csv))
    assert code == 0 and f"{events:,} events" in out
    assert log_name in both("logs", "list")
    assert f"{events:,}" in both("logs", "show", log_name)
    both("discover", "ekg", "--log", log_name, "--aggregate", "activity,robot")
    report = tmp_path / "perspectives.json"
    both("perspectives", "--log", log_name, "--json", str(report))
    assert report.is_file()
    code, _ = through("neo4j", uris, monkeypatch, capsys, "logs", "delete", log_name)
    assert code == 0
    assert log_name not in both("logs", "list")


def test_the_dashboard_reads_through_a_routing_uri(tmp_path, uris, monkeypatch):
    from robotale.webapp import create_app
    from robotale.webapp.settings import WebSettings

    pages = {}
    for scheme in ("neo4j", "bolt"):
        monkeypatch.setenv("NEO4J_URI", uris[scheme])
        app = create_app(
            WebSettings(
                upload_dir=tmp_path / scheme / "uploads",
                model_dir=tmp_path / scheme / "models",
                upload_limit_mb=5,
                secret_key="test",
            )
        )
        response = app.test_client().get("/logs")
        pages[scheme] = (response.status_code, "Neo4j is not" in response.get_data(as_text=True))
    assert pages["neo4j"] == pages["bolt"] == (200, False)
