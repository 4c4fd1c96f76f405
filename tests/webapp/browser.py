"""Debian's Chromium, headless, for the dashboard's browser tests and its benchmark (test-only).

Playwright (a development dependency) drives the system's Chromium (``/usr/bin/chromium``, or
``ROBOTALE_CHROMIUM``) rather than a browser it downloads. The flags keep Chromium from
reaching out on its own (updates, sync, field trials): on a closed network those connections
are refused and slow every page down.
"""

from __future__ import annotations

import os
import shutil
from pathlib import Path
from typing import Any

FLAGS = (
    "--headless",
    "--no-sandbox",
    "--disable-gpu",
    "--disable-quic",
    "--no-first-run",
    "--disable-background-networking",
    "--disable-component-update",
    "--disable-sync",
)
VIEWPORT = {"width": 1400, "height": 900}


def chromium_path() -> Path | None:
    """The Chromium to drive, or None when there is none."""
    found = os.environ.get("ROBOTALE_CHROMIUM") or shutil.which("chromium") or "/usr/bin/chromium"
    return Path(found) if Path(found).is_file() else None


def launch(playwright: Any, profile: Path) -> Any:
    """A browser context of a fresh Chromium with its profile in ``profile``."""
    path = chromium_path()
    if path is None:
        raise RuntimeError(
            "Debian's chromium is needed (make system-deps installs it), or ROBOTALE_CHROMIUM "
            "naming a Chromium binary."
        )
    return playwright.chromium.launch_persistent_context(
        profile, executable_path=str(path), headless=True, args=list(FLAGS), viewport=VIEWPORT
    )


def wait_for(page: Any, expression: str, timeout: float = 60.0) -> Any:
    """Wait until the JavaScript ``expression`` is truthy in ``page``; its value.

    Playwright's ``wait_for_function`` evaluates its predicate with ``eval`` inside the page,
    which the dashboard's Content-Security-Policy forbids (no 'unsafe-eval'); ``evaluate``
    goes through the DevTools protocol, which the policy does not govern.
    """
    import time

    deadline = time.monotonic() + timeout
    while True:
        value = page.evaluate(expression)
        if value:
            return value
        if time.monotonic() > deadline:
            raise TimeoutError(f"{expression} was still false after {timeout:.0f} s")
        page.wait_for_timeout(100)


def upload_model(page: Any, path: Path) -> None:
    """Upload a .bpmn on the Model page and wait until bpmn-js has drawn it."""
    from playwright.sync_api import expect  # the browser tests' extra, as in launch

    page.goto(page.base_url + "/model")
    page.set_input_files("input[name=model]", str(path))
    page.click("form.inline-form button[type=submit]")
    expect(page.locator("#canvas")).to_have_attribute("data-rendered", "1")
