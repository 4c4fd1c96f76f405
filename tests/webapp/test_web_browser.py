"""The dashboard in a real headless Chromium: what a user clicks, and what they see."""

from __future__ import annotations

import pytest
from playwright.sync_api import expect

pytestmark = pytest.mark.browser


def test_cypher_console_runs_an_example_and_refuses_a_write(page, screenshot, graph_counts):
    page.goto(page.base_url + "/cypher")
    page.click("button.example[data-name='ekg_server_version']")
    table = page.locator("#results table.data")
    expect(table.locator("th").first).to_have_text("name")
    expect(table.locator("tbody tr td").first).to_have_text("Neo4j Kernel")
    expect(page.locator("#status")).to_have_text("1 row")
    screenshot(page, "cypher")

    before = graph_counts()
    page.fill("#query", "CREATE (n:BrowserProbe) RETURN n")
    page.click("#run")
    expect(page.locator("#error")).to_contain_text("The console only reads")
    expect(page.locator("#results table")).to_have_count(0)
    assert graph_counts() == before
