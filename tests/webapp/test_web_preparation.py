"""A log whose pages nobody prepared (``robotale ingest --pages visit``): the first visit starts
their preparation in the dashboard, the page says how far it is and shows its results when
they are ready; in a real Neo4j and a real headless Chromium."""

from __future__ import annotations

import json
import shutil
import time
import uuid

import pandas as pd
import pytest
from browser import wait_for
from playwright.sync_api import expect

from robotale.enhancement.registry import page_names
from robotale.results.background import DONE, PROGRESS
from robotale.results.findings import PAGE_STEPS, stored_findings
from robotale.results.logdata import LogData


@pytest.fixture
def unprepared_log(neo4j_driver, thesis_csv):
    """The thesis' log stored as ``ingest --pages visit`` stores it: nothing prepared."""
    from robotale.ekg.build import build_ekg
    from robotale.ekg.logs import delete_log
    from robotale.eventlog.readers import read_log

    name = f"test_unprepared_{uuid.uuid4().hex[:8]}"
    log = read_log(thesis_csv, case_gap=pd.Timedelta("1h"))  # its five runs, a day apart
    build_ekg(neo4j_driver, log, name, entities=["robot", "msg_id"], progress=False)
    yield name
    delete_log(neo4j_driver, name)


def results(driver, name: str):
    from robotale.ekg.columnar import results_folder
    from robotale.results.logdata import current_build

    return results_folder(current_build(driver, name))


def test_the_first_question_starts_the_preparation_and_says_how_far_it_is(
    client, app, neo4j_driver, unprepared_log
):
    from robotale.webapp.state import state

    folder = results(neo4j_driver, unprepared_log)
    assert not (folder / DONE).exists()
    asked = f"/api/preparation?log={unprepared_log}&page=perspectives"
    first = client.get(asked).json
    assert first["ready"] is False
    seen = [first]
    deadline = time.monotonic() + 600
    while not (folder / DONE).exists():
        assert time.monotonic() < deadline, "the preparation did not finish"
        # as the pages ask: an answer that is not ready waits for the preparation to go on
        seen.append(client.get(f"/api/preparation?log={unprepared_log}&wait=1").json)
    # the findings, the class graph, each perspective, the runs, the first timeline, the
    # Mission page's slow-activity limits and its first run
    steps = 2 + len(page_names()) + 4
    progress = json.loads((folder / PROGRESS).read_text())
    assert (progress["done"], progress["total"]) == (steps, steps)
    assert len(set(progress["steps"])) == steps
    # the page that asked gets its own steps first, then the others in their order
    wanted = PAGE_STEPS["perspectives"]
    assert set(progress["steps"][: len(wanted)]) == set(wanted)
    assert progress["steps"][len(wanted)] == "findings"
    counted = [(s["done"], s["total"]) for s in seen if s["total"]]
    assert counted == sorted(counted) and all(done <= total for done, total in counted)
    assert client.get(asked).json["ready"] is True
    # a wait that is no number of seconds: one sentence, nothing started
    refused = client.get(f"{asked}&wait=soon")
    assert refused.status_code == 400
    assert refused.json["error"] == "the wait 'soon' is not a number of seconds of 0 or more."
    # one preparation, however often it was asked: each result computed once, then kept
    computed = state(app).logs.computed
    assert computed[(unprepared_log, "findings")] == 1
    assert computed[(unprepared_log, "perspective")] == len(page_names())
    kept = LogData()
    stored_findings(neo4j_driver, kept, unprepared_log)
    assert not kept.computed  # read from what the preparation kept
    # its kept results removed (by hand, say): the next question prepares them again
    shutil.rmtree(folder)
    assert client.get(asked).json["ready"] is False
    deadline = time.monotonic() + 600
    while not (folder / DONE).exists():
        assert time.monotonic() < deadline, "the second preparation did not finish"
        time.sleep(0.2)
    assert computed[(unprepared_log, "findings")] == 2


browser = pytest.mark.browser


@browser
def test_a_page_visited_first_shows_the_preparation_then_its_results(
    page, neo4j_driver, unprepared_log, thesis_csv
):
    page.goto(f"{page.base_url}/findings?log={unprepared_log}")
    box = page.locator("#preparing")
    expect(box).to_be_visible()
    expect(box).to_contain_text(f"preparing the pages of {unprepared_log} …")
    findings = page.locator("#findings")
    expect(findings).to_have_attribute("data-state", "shown", timeout=600_000)
    expect(box).to_be_hidden()
    assert page.evaluate("performance.getEntriesByName('robotale-prepared').length") == 1
    # the runs the page lists: the thesis' five days, counted from the CSV
    days = pd.to_datetime(pd.read_csv(thesis_csv)["time"]).dt.date.nunique()
    assert page.locator("#runs-table tbody tr").count() == days
    assert json.loads((results(neo4j_driver, unprepared_log) / PROGRESS).read_text())["steps"]


@browser
def test_a_prepared_log_shows_no_preparation(page, neo4j_driver, unprepared_log):
    from robotale.results.background import prepare_now

    prepare_now(neo4j_driver, unprepared_log)
    page.goto(f"{page.base_url}/perspectives?log={unprepared_log}")
    wait_for(page, "performance.getEntriesByName('robotale-perspectives-drawn').length", 600)
    assert page.evaluate("performance.getEntriesByName('robotale-prepared').length") == 0
    expect(page.locator("#preparing")).to_be_hidden()
