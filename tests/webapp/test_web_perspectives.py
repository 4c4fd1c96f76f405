"""The Perspectives page draws every section's figures with the data of the log: the points and
bars plotly holds once the page is fully drawn, against what pandas counts in the same log.
The sections below the window are asked for, and the figures below the fold drawn, after the
page's ``robotale-perspectives-drawn`` mark; a 3D figure (WebGL) once it is scrolled into the
window."""

from __future__ import annotations

import re
from itertools import pairwise

import mission_findings as mission
import pytest
from browser import wait_for
from playwright.sync_api import expect
from test_web_findings import _store  # stored as the Findings tests store theirs

from robotale.eventlog import schema

pytestmark = pytest.mark.browser

#: every figure of every section once drawn: its section and, per trace, what plotly drew
DRAWN_FIGURES = """() => [...document.querySelectorAll('article.perspective .figure')]
  .map((box) => ({
    section: box.dataset.section,
    plotted: box.dataset.plotted || null,
    traces: (box._fullData || []).map((t) => ({
        type: t.type, name: t.name, mode: t.mode || null, points: t._length,
        x: t.type === 'bar' ? Array.from(t.x || [], String) : null,
    })),
}))"""
ALL_DRAWN = "performance.getEntriesByName('robotale-perspectives-all-drawn').length > 0"


@pytest.fixture(scope="module")
def thesis_log(neo4j_driver, thesis_csv):
    """The thesis' five runs (positions, messages, no battery): the log and its stored name."""
    from robotale.ekg.logs import delete_log
    from robotale.eventlog.readers import read_log

    log = read_log(thesis_csv)
    name = _store(neo4j_driver, log, "test_paint_thesis")
    yield log, name
    delete_log(neo4j_driver, name)


@pytest.fixture(scope="module")
def battery_log(neo4j_driver, tmp_path_factory):
    """The injected mission (battery levels of every robot): the log and its stored name."""
    from robotale.ekg.logs import delete_log
    from robotale.eventlog.readers import read_log

    path = mission.write_injected("robotale.csv", tmp_path_factory.mktemp("b") / "mission.csv")
    log = read_log(path)
    name = _store(neo4j_driver, log, "test_paint_battery")
    yield log, name
    delete_log(neo4j_driver, name)


def drawn(page, log: str) -> list[dict]:
    """Open the page of ``log``, wait until every figure is drawn (those drawn only in the
    window scrolled to); what plotly drew."""
    page.goto(f"{page.base_url}/perspectives?log={log}")
    wait_for(page, ALL_DRAWN, timeout=120)
    waiting = page.locator("article.perspective .figure:has(> .placeholder)")
    while left := waiting.count():
        waiting.first.scroll_into_view_if_needed()
        wait_for(page, f"document.querySelectorAll('.figure > .placeholder').length < {left}", 120)
    return page.evaluate(DRAWN_FIGURES)


def traces(figures: list[dict], section: str, kind: str) -> list[dict]:
    return [t for f in figures if f["section"] == section for t in f["traces"] if t["type"] == kind]


def test_every_figure_is_drawn_after_the_visible_ones(page, thesis_log):
    _, name = thesis_log
    figures = drawn(page, name)
    sections = {f["section"] for f in figures}
    assert {"bottlenecks", "spatial", "communication", "performance"} <= sections
    assert all(f["plotted"] == str(len(f["traces"])) for f in figures), figures
    marks = page.evaluate(
        "['robotale-perspectives-drawn', 'robotale-perspectives-all-drawn']"
        ".map((m) => performance.getEntriesByName(m)[0].startTime)"
    )
    assert marks[0] <= marks[1]


def test_spatial_draws_every_placed_event_by_activity(page, thesis_log):
    log, name = thesis_log
    placed = log.dropna(subset=["x", "y"]).groupby(schema.ACTIVITY).size()
    figures = drawn(page, name)
    points = {t["name"]: t["points"] for t in traces(figures, "spatial", "scatter3d")}
    assert points == {str(a): int(n) for a, n in placed.items()}


def test_the_3d_figure_is_drawn_when_scrolled_into_view(page, thesis_log):
    """Every other figure is drawn without being looked at; the spatial section's 3D scatter
    says it is drawn when scrolled to, and is, with every placed event, once in the window."""
    log, name = thesis_log
    page.goto(f"{page.base_url}/perspectives?log={name}")
    wait_for(page, ALL_DRAWN, timeout=120)
    spatial = page.locator("article[data-name=spatial] .figure")
    expect(spatial).to_have_count(1)
    expect(spatial.locator("> .placeholder")).to_have_text(
        "3D figure: drawn when scrolled into view"
    )
    figures = page.evaluate(DRAWN_FIGURES)
    waiting = [f for f in figures if not f["plotted"]]
    assert [f["section"] for f in waiting] == ["spatial"] and not waiting[0]["traces"]
    assert all(f["plotted"] == str(len(f["traces"])) for f in figures if f["plotted"])

    spatial.scroll_into_view_if_needed()
    expect(spatial.locator("> .placeholder")).to_have_count(0)
    expect(spatial).to_have_attribute("data-plotted", re.compile("[1-9]"))
    points = {
        t["name"]: t["points"] for t in traces(page.evaluate(DRAWN_FIGURES), "spatial", "scatter3d")
    }
    placed = log.dropna(subset=["x", "y"]).groupby(schema.ACTIVITY).size()
    assert points == {str(a): int(n) for a, n in placed.items()}


def test_performance_draws_a_bar_for_every_case(page, thesis_log):
    log, name = thesis_log
    cases = set(log[schema.CASE].astype(str))
    figures = drawn(page, name)
    per_case = [f for f in figures if f["section"] == "performance"]
    bars = [set(t["x"]) for f in per_case for t in f["traces"] if t["type"] == "bar"]
    assert cases in bars, bars


def test_battery_draws_every_level_of_every_robot(page, battery_log):
    log, name = battery_log
    with_levels = log.dropna(subset=[schema.BATTERY]).groupby(schema.ROBOT)
    levels = with_levels.size()
    # each robot's line breaks between its runs: one gap (a point without a value) per break
    gaps = with_levels[schema.CASE].nunique() - 1
    figures = drawn(page, name)
    lines = traces(figures, "battery", "scatter")
    assert {t["name"]: t["points"] for t in lines if t["mode"] == "lines"} == {
        str(r): int(n) + int(gaps[r]) for r, n in levels.items()
    }


#: each section's request: its name, when it started and when it ended (ms)
FETCHES = """() => performance.getEntriesByType('measure')
  .filter((m) => m.name.startsWith('robotale-fetch ') && m.name !== 'robotale-fetch graph')
  .map((m) => [m.name.slice(15), m.startTime, m.startTime + m.duration])"""


def test_the_sections_below_the_window_load_after_the_first_view(page, thesis_log):
    _, name = thesis_log
    page.goto(f"{page.base_url}/perspectives?log={name}")
    wait_for(page, ALL_DRAWN, timeout=120)
    fetches = page.evaluate(FETCHES)
    first_view = page.evaluate(
        "performance.getEntriesByName('robotale-perspectives-drawn')[0].startTime"
    )
    # one after the other, in the page's order, each asked for once
    order = page.evaluate(
        "[...document.querySelectorAll('article.perspective')].map((a) => a.dataset.name)"
    )
    assert [n for n, _, _ in fetches] == order
    assert all(a[2] <= b[1] for a, b in pairwise(fetches))
    # the first section was there for the first view; the last (below the bottleneck ranking,
    # its figure and four other sections in a 900-pixel window) came after it, and then shown
    assert fetches[0][2] <= first_view < fetches[-1][2]
    states = page.evaluate(
        "[...document.querySelectorAll('article.perspective')].map((a) => a.dataset.state)"
    )
    assert set(states) <= {"shown", "empty"}, states
