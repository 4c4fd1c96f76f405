"""Every app-level object of the dashboard belongs to its app, none to a module."""

from __future__ import annotations

from robotale.sim import scenarios
from robotale.webapp import create_app
from robotale.webapp.settings import WebSettings
from robotale.webapp.state import state


def settings(folder) -> WebSettings:
    return WebSettings(upload_dir=folder / "uploads", model_dir=folder / "models", secret_key="x")


def test_two_apps_share_nothing(tmp_path):
    first, second = (create_app(settings(tmp_path / name)) for name in ("a", "b"))
    mine, theirs = state(first), state(second)
    assert mine.settings.model_dir == tmp_path / "a" / "models"
    for name in ("settings", "models", "neo4j", "jobs", "pending", "logs", "overlays"):
        assert getattr(mine, name) is not getattr(theirs, name), name
    shipped = sorted(p.name for p in scenarios.FOLDER.glob("*.bpmn"))
    assert sorted(m.name for m in mine.models.all()) == shipped
    with first.app_context():
        assert state() is mine


def test_forgetting_a_log_empties_only_that_apps_caches(tmp_path):
    first, second = (create_app(settings(tmp_path / name)) for name in ("a", "b"))
    for app in (first, second):
        state(app).logs.graphs.get(("agri", "v1", ("activity",), None), lambda: {"nodes": []})
    state(first).logs.forget("agri")
    assert list(state(first).logs.graphs.items) == []
    assert list(state(second).logs.graphs.items) == [("agri", "v1", ("activity",), None)]
