"""The dashboard in a real headless Chromium: what a user clicks, and what they see."""

from __future__ import annotations

import csv
import re
import subprocess
import sys

import pytest
from browser import upload_model, wait_for
from playwright.sync_api import expect

pytestmark = pytest.mark.browser


def test_cypher_console_runs_a_query_and_refuses_a_write(page, screenshot, graph_counts):
    from importlib.resources import files

    page.goto(page.base_url + "/cypher")
    version = files("robotale.cypher").joinpath("ekg_server_version.cypher").read_text()
    page.fill("#query", version)
    page.click("#run")
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
    upload_model(page, agri)
    drawn = set(
        page.eval_on_selector_all("[data-element-id]", "els => els.map(e => e.dataset.elementId)")
    )
    expected = {node.id for _, process in parse(agri).pools() for node in process.walk()}
    assert expected and expected <= drawn
    expect(page.locator("#model-picker option:checked")).to_contain_text("agri.bpmn")


SCENARIO_LOG = "robotic_data_test"


@pytest.fixture
def scenario_log(neo4j_driver):
    """A fixed log name (the screenshots show it), empty before and after the test."""
    from robotale.ekg.logs import delete_log

    delete_log(neo4j_driver, SCENARIO_LOG)
    yield SCENARIO_LOG
    delete_log(neo4j_driver, SCENARIO_LOG)


def thesis_counts(thesis_csv) -> tuple[int, set[tuple[str, str]], int]:
    with thesis_csv.open(newline="") as stream:
        rows = list(csv.DictReader(stream))
    pairs = {(r["activity"], r["resource"]) for r in rows}
    explore = sum(1 for r in rows if r["activity"] == "explore" and r["resource"] == "drone")
    return len(rows), pairs, explore


#: the activity (class) nodes cytoscape draws, in the page's JavaScript
CLASSES = "document.getElementById('graph')._cy.nodes('[kind = \"activity\"]')"


def drawn_classes(page) -> int:
    return page.evaluate(f"() => {CLASSES}.length")


def click_node(page, where: str) -> None:
    """Click the node of the graph that ``where`` (a JS predicate on its data) picks."""
    position = page.evaluate(
        f"""() => {{
            const cy = document.getElementById('graph')._cy;
            const picks = (n) => {{ const node = n.data('node'); return {where}; }};
            return cy.nodes().filter(picks)[0].renderedPosition();
        }}"""
    )
    box = page.locator("#graph").bounding_box()
    page.mouse.click(box["x"] + position["x"], box["y"] + position["y"])


def test_upload_ingest_discover_and_drill_down(page, screenshot, thesis_csv, scenario_log):
    events, pairs, explore = thesis_counts(thesis_csv)

    # Logs: upload the thesis CSV, keep the proposed columns, store it.
    page.goto(page.base_url + "/logs")
    page.set_input_files("input[name=file]", str(thesis_csv))
    page.click("#upload-form button[type=submit]")
    expect(page.locator("#columns-form")).to_be_visible()
    expect(page.locator("tr[data-column=robot] input[name=entity]")).to_be_checked()
    expect(page.locator("tr[data-column=msg_id] input[name=entity]")).to_be_checked()
    page.fill("#log-name", scenario_log)
    screenshot(page, "logs-columns")
    page.click("#ingest")
    expect(page.locator("#job")).to_have_attribute("data-state", "done")
    expect(page.locator("#job-events")).to_have_text(str(events))
    expect(page.locator("#job-progress")).to_have_attribute("value", "1")

    # Discover: the EKG aggregated by activity and robot comes first.
    page.click("#discover-link")
    expect(page.locator("#graph")).to_have_attribute("data-kind", "ekg")
    expect(page.locator("#graph")).to_have_attribute("data-drawn", re.compile(r"\d+"))
    assert drawn_classes(page) == len(pairs)
    expect(page.locator("#legend")).to_contain_text("tractor_2")

    # Change the aggregation: by activity alone, then by activity and robot again.
    page.uncheck("input[name=by][value=robot]")
    wait_for(page, f"{CLASSES}.length === {len({a for a, _ in pairs})}")
    page.check("input[name=by][value=robot]")
    wait_for(page, f"{CLASSES}.length === {len(pairs)}")
    expect(page.locator("#graph")).to_have_attribute("data-drawn", re.compile(r"\d+"))

    # Zoom with the wheel and pan by dragging the background.
    cy_zoom = "() => document.getElementById('graph')._cy.zoom()"
    cy_pan = "() => document.getElementById('graph')._cy.pan().x"
    before_zoom, before_pan = page.evaluate(cy_zoom), page.evaluate(cy_pan)
    box = page.locator("#graph").bounding_box()
    page.mouse.move(box["x"] + 15, box["y"] + 15)
    page.mouse.wheel(0, -400)
    wait_for(page, f"document.getElementById('graph')._cy.zoom() > {before_zoom}")
    page.mouse.down()
    page.mouse.move(box["x"] + 200, box["y"] + 60, steps=8)
    page.mouse.up()
    assert page.evaluate(cy_pan) != before_pan
    page.click("#fit")

    # Click the drone's explore class: its details and where it happened.
    click_node(page, "node.properties.activity === 'explore' && node.properties.robot === 'drone'")
    expect(page.locator("#details-title")).to_have_text("explore by drone")
    expect(page.locator("#spatial-figure")).to_have_attribute("data-plotted", re.compile(r"\d+"))
    expect(page.locator("#node-figure-message")).to_contain_text(f"positions: {explore}")
    expect(page.locator("#spatial-figure .main-svg").first).to_be_visible()
    screenshot(page, "discover")

    # The DFG tab, filtered to the drone.
    page.click("#tab-dfg")
    expect(page.locator("#graph")).to_have_attribute("data-kind", "dfg")
    page.select_option("#filter-robot", ["drone"])
    page.click("#dfg-form button[type=submit]")
    wait_for(page, f"{CLASSES}.every((n) => n.data('node').robot === 'drone')")
    screenshot(page, "dfg-drone")

    # All perspectives of the drone's explore class.
    page.click("#tab-ekg")
    expect(page.locator("#graph")).to_have_attribute("data-kind", "ekg")
    wait_for(page, "document.getElementById('graph').dataset.drawn")
    click_node(page, "node.properties.activity === 'explore' && node.properties.robot === 'drone'")
    page.click("#details-link")
    expect(page.locator("#focus-label")).to_have_text("explore by drone")
    for name in ("spatial", "communication", "battery", "performance"):
        expect(page.locator(f"article[data-name={name}]")).to_have_attribute(
            "data-state", re.compile("shown|empty")
        )
    # the 3D figure is drawn once it is in the window
    page.locator("article[data-name=spatial] .figure").scroll_into_view_if_needed()
    expect(page.locator("article[data-name=spatial] .figure[data-plotted]")).to_have_count(1)
    screenshot(page, "perspectives")
    page.click("#whole-log")
    expect(page.locator("#focus-label")).to_have_text("the whole log")
    expect(page.locator("article[data-name=spatial]")).to_have_attribute("data-state", "shown")
    expect(page.locator("article[data-name=spatial] .summary")).to_contain_text(
        f"positions: {events}"
    )


@pytest.fixture
def crashed_drone_log(neo4j_driver, tmp_path):
    """Two agri runs in which the drone dies after 20 s, stored as the log ``agri_test``."""
    from robotale.ekg.build import build_ekg
    from robotale.ekg.logs import delete_log
    from robotale.eventlog.prepare import prepare

    out = tmp_path / "agri"
    command = [sys.executable, "-m", "robotale", "simulate", "agri", "--runs", "2", "--weeds", "3"]
    command += ["--tractors", "2", "--fault", "die:drone@20", "--out", str(out), "--workers", "0"]
    subprocess.run([*command, "--quiet"], check=True, capture_output=True)
    log = prepare(out)
    name = "agri_test"
    build_ekg(neo4j_driver, log, name, entities=["robot", "msg_id"], replace=True, progress=False)
    yield name, log
    delete_log(neo4j_driver, name)


def test_model_page_shades_frequencies_and_outlines_deviations(page, screenshot, crashed_drone_log):
    from robotale.discovery import activity_instances

    name, log = crashed_drone_log
    page.goto(f"{page.base_url}/model?log={name}")
    expect(page.locator("#model-picker option:checked")).to_contain_text("agri.bpmn")
    expect(page.locator("#canvas")).to_have_attribute("data-painted", re.compile(r"\d+"))
    instances = activity_instances(log)
    take_offs = int(
        ((instances["concept:name"] == "take_off") & (instances["robot"] == "drone")).sum()
    )
    assert take_offs == 2  # one per run
    expect(page.locator(".count-badge[data-element=Drone_TakeOff]").first).to_have_text(
        str(take_offs)
    )
    shaded = page.eval_on_selector(
        "[data-element-id=Drone_TakeOff] .djs-visual > :first-child", "e => e.style.fill"
    )
    assert shaded and shaded != "rgb(255, 255, 255)"

    # The drone died before it could return and land: those are missing in both runs.
    expect(page.locator("#canvas")).to_have_attribute("data-deviations", re.compile(r"\d+"))
    for element in ("Drone_ReturnToBase", "Drone_Land"):
        badge = page.locator(f".count-badge.deviating[data-element={element}]")
        expect(badge).to_have_text("2 missing")
    expect(page.locator("#model-summary table")).to_contain_text("drone")
    assert not page.locator(".count-badge.deviating[data-element=Tractor_CutGrass]").count()
    screenshot(page, "model")


def test_a_discovered_collaboration_is_drawn_whole_without_overlaps(page, thesis_csv, tmp_path):
    """``discover bpmn`` on the thesis log, drawn by the Model page's bpmn-js: every element
    of the file has its shape, and no two shapes (pools and sub-processes apart from what
    they contain) cover each other on the screen."""
    from robotale.discovery.bpmn_writer import write_bpmn
    from robotale.discovery.collaboration import discover_collaboration
    from robotale.eventlog.readers import read_log
    from robotale.fame_runtime.parser import parse

    model = tmp_path / "discovered.bpmn"
    model.write_text(write_bpmn(discover_collaboration(read_log(thesis_csv, case_gap="1h"))))
    upload_model(page, model)
    boxes = page.eval_on_selector_all(
        ".djs-shape[data-element-id]",
        """els => els.map(e => {
            const r = e.getBoundingClientRect();
            return [e.dataset.elementId, r.x, r.y, r.width, r.height];
        })""",
    )
    drawn = {box[0] for box in boxes}
    expected = {node.id for _, process in parse(model).pools() for node in process.walk()}
    assert expected and expected <= drawn
    containers = {i for i in drawn if i.startswith("Pool_") or "_subprocess_" in i}
    shapes = [b for b in boxes if b[0] not in containers and not b[0].endswith("_label")]
    overlapping = [
        (a[0], b[0])
        for n, a in enumerate(shapes)
        for b in shapes[n + 1 :]
        if a[1] < b[1] + b[3] - 1 and b[1] < a[1] + a[3] - 1
        and a[2] < b[2] + b[4] - 1 and b[2] < a[2] + a[4] - 1
    ]  # fmt: skip
    assert overlapping == []
