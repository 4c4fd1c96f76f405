"""Fixtures of the dashboard's tests: the app against the session's real Neo4j, the app served
on a free port, and a real headless Chromium driven by Playwright.

Chromium is Debian's (``/usr/bin/chromium``, or ``ROBOTALE_CHROMIUM``); Playwright only drives
it, so no browser is downloaded. Every page a test opens refuses requests that leave the
dashboard, which proves the pages need no CDN, and fails the test on a JavaScript error.
"""

from __future__ import annotations

import os
import re
from collections.abc import Iterator
from pathlib import Path
from urllib.parse import urlsplit

import pytest


@pytest.fixture(scope="session")
def web_settings(tmp_path_factory: pytest.TempPathFactory):
    from robotale.webapp.settings import WebSettings

    return WebSettings(
        upload_dir=tmp_path_factory.mktemp("uploads"),
        model_dir=tmp_path_factory.mktemp("models"),
        upload_limit_mb=50,
        secret_key="test",
    )


@pytest.fixture(scope="session")
def app(neo4j_server, web_settings):
    """The dashboard against the session's Neo4j."""
    from robotale.webapp import create_app

    return create_app(web_settings)


@pytest.fixture
def client(app):
    """A Flask test client whose ``csrf`` attribute holds a valid CSRF token."""
    client = app.test_client()
    page = client.get("/cypher").get_data(as_text=True)
    client.csrf = re.search(r'name="csrf-token" content="([^"]+)"', page).group(1)
    return client


@pytest.fixture(scope="session")
def dashboard(app) -> Iterator[object]:
    """The app served over HTTP on a free port of 127.0.0.1."""
    from robotale.webapp.serve import Dashboard

    with Dashboard(app, port=0) as running:
        yield running


@pytest.fixture(scope="session")
def browser_context(tmp_path_factory: pytest.TempPathFactory) -> Iterator[object]:
    """A headless Chromium with a fresh profile."""
    from playwright.sync_api import expect, sync_playwright

    # The machine may be busy: wait for what the user would wait for, not for a fixed 5 s.
    expect.set_options(timeout=60_000)
    from browser import chromium_path, launch

    if chromium_path() is None:
        pytest.fail(
            "The browser tests need Debian's chromium (make system-deps installs it) "
            "or ROBOTALE_CHROMIUM naming a Chromium binary."
        )
    with sync_playwright() as playwright:
        context = launch(playwright, tmp_path_factory.mktemp("chromium-profile"))
        context.set_default_timeout(60_000)
        yield context
        context.close()


@pytest.fixture
def page(browser_context, dashboard) -> Iterator[object]:
    """A new tab that may only talk to the dashboard; JavaScript errors fail the test."""
    tab = browser_context.new_page()
    errors: list[str] = []
    outside: list[str] = []
    dashboard_origin = urlsplit(dashboard.url).netloc

    def guard(route) -> None:
        if urlsplit(route.request.url).netloc == dashboard_origin:
            route.continue_()
        else:
            outside.append(route.request.url)
            route.abort()

    tab.route("**/*", guard)
    tab.on("pageerror", lambda error: errors.append(str(error)))
    tab.base_url = dashboard.url
    yield tab
    tab.close()
    assert not outside, f"the page asked for resources outside the dashboard: {outside}"
    assert not errors, f"JavaScript errors: {errors}"


@pytest.fixture(scope="session")
def screenshot(tmp_path_factory: pytest.TempPathFactory):
    """Save a screenshot of a page as ``<name>.png``.

    They go to a temporary folder, or to ``ROBOTALE_SCREENSHOT_DIR``: the pictures in the docs
    come from ``ROBOTALE_SCREENSHOT_DIR=docs/screenshots pytest -m browser tests/webapp``.
    """
    configured = os.environ.get("ROBOTALE_SCREENSHOT_DIR")
    folder = Path(configured) if configured else tmp_path_factory.mktemp("screenshots")

    def take(tab, name: str) -> Path:
        folder.mkdir(parents=True, exist_ok=True)
        path = folder / f"{name}.png"
        tab.screenshot(path=str(path))
        return path

    return take
