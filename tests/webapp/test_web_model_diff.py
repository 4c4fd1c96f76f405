"""The Model page's diff: the agri scenario's model, which drove two simulated runs, against
the model discovered from them, in a real headless Chromium; the expected marks are read here
from the models' XML with lxml and the runs' log."""

from __future__ import annotations

from urllib.parse import parse_qs, urlparse

import pytest
from browser import upload_model
from lxml import etree
from playwright.sync_api import expect

BPMNDI = "{http://www.omg.org/spec/BPMN/20100524/DI}"


@pytest.fixture(scope="module")
def models(tmp_path_factory):
    from discovered_agri import agri_discovered

    return agri_discovered(tmp_path_factory.mktemp("model_diff"))


def test_diff_api_refuses_an_unknown_model(client):
    answer = client.get("/api/models/0000000000000000/diff?against=nope")
    assert answer.status_code == 400 and "no stored model" in answer.json["error"]


@pytest.mark.browser
def test_model_page_outlines_what_the_robots_never_used(page, models):
    driving, discovered, log = models
    ids = []
    for path in (discovered, driving):
        upload_model(page, path)
        ids.append(parse_qs(urlparse(page.url).query)["model"][0])
    drawn = {
        shape.get("bpmnElement")
        for shape in etree.parse(str(driving)).iter(f"{BPMNDI}BPMNShape", f"{BPMNDI}BPMNEdge")
    }
    # the Tractor's battery handler: no tractor ran low in these runs (counted from the log)
    tractors = log[log["robot_type"] == "Tractor"]["concept:name"].astype(str)
    assert "low_battery" not in set(tractors)
    page.select_option("#diff-picker", ids[0])
    page.click("#diff")
    lists = page.locator("#diff-findings ul")
    expect(lists.first).to_contain_text("Tractor: low_battery")
    unused = page.locator("#canvas").get_attribute("data-unused").split()
    assert set(unused) <= drawn
    marked = page.locator("#canvas .unused")
    expect(marked).to_have_count(len(unused))
    # the tractor's low_battery start event is one of them
    tree = etree.parse(str(driving))
    bpmn = "{http://www.omg.org/spec/BPMN/20100524/MODEL}"
    tractor = next(p for p in tree.iter(f"{bpmn}process") if p.get("name") == "Tractor")
    low = [e.get("id") for e in tractor.iter(f"{bpmn}startEvent") if e.get("name") == "low_battery"]
    assert low and set(low) <= set(unused)
