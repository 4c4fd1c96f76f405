"""The Discover page's aggregation form: its endpoints (CSRF, bad input, run, draw a level,
undo) on a small log in the real Neo4j, and the form in a real headless Chromium."""

from __future__ import annotations

import uuid

import pytest
from playwright.sync_api import expect

# r1: move, spray, move; r2: move, spray
SMALL = """case,activity,time,robot,event_id
c1,move,2024-01-01T10:00:00Z,r1,e1
c1,spray,2024-01-01T10:01:00Z,r1,e2
c1,move,2024-01-01T10:02:00Z,r2,e3
c1,spray,2024-01-01T10:03:00Z,r2,e4
c1,move,2024-01-01T10:04:00Z,r1,e5
"""
SPEC = "steps:\n  - {aggr_type: EVENTS, group_by: [activity]}\n"


@pytest.fixture
def small_log(tmp_path, neo4j_driver):
    from robotale.ekg.build import build_ekg
    from robotale.ekg.logs import delete_log
    from robotale.eventlog.readers import read_csv

    path = tmp_path / "small.csv"
    path.write_text(SMALL)
    name = f"test_aggregation_{uuid.uuid4().hex[:8]}"
    build_ekg(neo4j_driver, read_csv(path), name, entities=["robot"], progress=False)
    yield name
    delete_log(neo4j_driver, name)


def post(client, path: str, body: dict, csrf: bool = True):
    headers = {"X-CSRFToken": client.csrf} if csrf else {}
    return client.post(path, json=body, headers=headers)


def test_run_draw_and_undo(client, small_log, graph_counts):
    before = graph_counts()
    assert (
        post(
            client, "/api/aggregation/run", {"log": small_log, "spec": SPEC}, csrf=False
        ).status_code
        == 400
    )
    assert graph_counts() == before
    bad = post(client, "/api/aggregation/run", {"log": small_log, "spec": "steps: [\n"})
    assert bad.status_code == 400 and "not valid YAML at line" in bad.json["error"]
    speed = "steps:\n  - {aggr_type: EVENTS, group_by: [speed]}\n"
    unknown = post(client, "/api/aggregation/run", {"log": small_log, "spec": speed})
    assert unknown.status_code == 400 and "no property 'speed'" in unknown.json["error"]
    assert graph_counts() == before

    ran = post(client, "/api/aggregation/run", {"log": small_log, "spec": SPEC})
    assert ran.status_code == 200
    [result] = ran.json["results"]
    assert (result["initial_events"], result["final_events"], result["aggregates"]) == (5, 0, 2)
    graph = client.get(f"/api/aggregation/graph?log={small_log}&level=1").json
    counts = {n["label"].split("\n")[0]: n["count"] for n in graph["nodes"]}
    assert counts == {"move": 3, "spray": 2}
    # DF of r1 e1->e2->e5 and of r2 e3->e4: move->spray twice, spray->move once
    flows = {(e["source"], e["target"]): e["count"] for e in graph["edges"]}
    assert flows == {("1:move", "1:spray"): 2, ("1:spray", "1:move"): 1}
    steps = client.get(f"/api/aggregation/steps?log={small_log}").json["steps"]
    assert [s["step"] for s in steps] == [1]

    assert post(client, "/api/aggregation/undo", {"log": small_log}).json == {"undone": [1]}
    assert graph_counts() == before
    missing = client.get("/api/aggregation/graph?log=nothing&level=1")
    assert missing.status_code == 400 and "'nothing'" in missing.json["error"]
    assert client.get(f"/api/aggregation/graph?log={small_log}&level=x").status_code == 400


@pytest.mark.browser
def test_the_form_runs_a_specification_and_draws_it(page, small_log):
    page.goto(page.base_url + f"/discover?log={small_log}")
    page.click("#tab-aggregation")
    expect(page.locator("#graph-status")).to_contain_text("No aggregation steps yet")
    page.fill("#aggregation-spec", SPEC)
    page.click("#aggregation-form button[type=submit]")
    expect(page.locator("#graph")).to_have_attribute("data-kind", "aggregates")
    expect(page.locator("#graph-status")).to_have_text("Level 1: 2 aggregates, 2 edges")
    expect(page.locator("#aggregation-steps")).to_contain_text("2 aggregates")
    page.click("#aggregation-undo")
    expect(page.locator("#graph-status")).to_contain_text("No aggregation steps yet")
