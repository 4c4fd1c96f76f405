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


def test_model_page_draws_an_uploaded_collaboration(page, fame_models):
    from robotale.fame_runtime.parser import parse

    agri = fame_models / "fame-ros" / "agri.bpmn"
    page.goto(page.base_url + "/model")
    page.set_input_files("input[name=model]", str(agri))
    page.click("form.inline-form button[type=submit]")
    expect(page.locator("#canvas")).to_have_attribute("data-rendered", "1")
    drawn = set(
        page.eval_on_selector_all("[data-element-id]", "els => els.map(e => e.dataset.elementId)")
    )
    expected = {node.id for _, process in parse(agri).pools() for node in process.walk()}
    assert expected and expected <= drawn
    expect(page.locator("#model-picker option:checked")).to_contain_text("agri.bpmn")
