"""The Compare page on two stored logs: the mission with injected findings
(``tests/mission_findings.py``) and the same mission without the runs that wait for a refill;
in a real Neo4j and, for the page itself, a real headless Chromium."""

from __future__ import annotations

import uuid

import mission_findings as mission
import pandas as pd
import pytest
from playwright.sync_api import expect

from robotale.enhancement.compare import compare_logs
from robotale.eventlog.schema import CASE


@pytest.fixture(scope="module")
def two_logs(neo4j_driver, tmp_path_factory):
    """(A, B): A without the refill runs, B all twelve runs; stored once for this module."""
    from robotale.ekg.build import build_ekg
    from robotale.ekg.keys import built_keys
    from robotale.ekg.logs import delete_log
    from robotale.eventlog.readers import read_log

    path = mission.write_injected("robotale.csv", tmp_path_factory.mktemp("c") / "mission.csv")
    full = read_log(path)
    calm = full[~full["case:concept:name"].isin(mission.REFILL_RUNS)].reset_index(drop=True)
    names = []
    for prefix, log in (("test_compare_a", calm), ("test_compare_b", full)):
        name = f"{prefix}_{uuid.uuid4().hex[:8]}"
        entities = ["robot", "msg_id"]
        build_ekg(
            neo4j_driver,
            log,
            name,
            entities=entities,
            aggregate=built_keys(entities),
            progress=False,
        )
        names.append(name)
    yield names, calm, full
    for name in names:
        delete_log(neo4j_driver, name)


def test_compare_page_refuses_an_unknown_log(client, two_logs):
    names, _, _ = two_logs
    answer = client.get(f"/compare?a={names[0]}&b=no_such_log_here")
    assert answer.status_code in (400, 404)
    assert b"no_such_log_here" in answer.data


@pytest.mark.browser
def test_compare_page_shows_the_sentences_and_tables(page, two_logs, screenshot):
    names, calm, full = two_logs
    expected = compare_logs(calm, full)
    # the refill runs are a third of B: their variant appeared, the others are in both
    refill = [v for v in expected.variants.itertuples() if mission.REFILL in v.variant]
    assert refill and all(v.status == "appeared" for v in refill)
    assert sum(v.runs_b for v in refill) == len(mission.REFILL_RUNS)
    page.goto(f"{page.base_url}/compare")
    expect(page.locator("nav a[data-endpoint='compare.page']")).to_have_text("Compare")
    page.select_option("select[name=a]", names[0])
    page.select_option("select[name=b]", names[1])
    page.click("form.compare-form button[type=submit]")
    items = page.locator("#compare-sentences li")
    expect(items).to_have_count(len(expected.sentences))
    assert items.all_inner_texts() == expected.sentences
    rows = page.locator("#compare-changes tbody tr")
    expect(rows).to_have_count(len(expected.changes))
    expect(page.locator("#compare-variants tbody tr")).to_have_count(len(expected.variants))
    screenshot(page, "compare")


def test_compare_command_reads_stored_logs_and_files(two_logs, tmp_path, capsys):
    """``robotale compare`` of the two stored logs, then of A's file against B's stored log:
    the same runs compared, counted here from the logs themselves."""
    import json

    from robotale.cli import main

    names, calm, full = two_logs
    out = tmp_path / "compare.json"
    assert main(["compare", names[0], names[1], "--json", str(out)]) == 0
    stored = json.loads(out.read_text(encoding="utf-8"))
    assert stored["facts"]["runs"] == [calm[CASE].nunique(), full[CASE].nunique()]
    assert stored["sentences"][0] in capsys.readouterr().out
    path = tmp_path / "a.csv"
    calm.to_csv(path, index=False)
    assert main(["compare", str(path), names[1], "--json", str(out)]) == 0
    mixed = json.loads(out.read_text(encoding="utf-8"))
    assert mixed["sentences"] == stored["sentences"]


@pytest.mark.browser
def test_compare_page_draws_each_batchs_runs(page, two_logs):
    """The first figure is the runs' durations: its A and B boxes hold one point per run, each
    the run's first to last event, counted here by pandas from the two logs; the figures after
    it are the first tested changes, each with a box per batch."""
    names, calm, full = two_logs
    expected = compare_logs(calm, full)
    page.goto(f"{page.base_url}/compare?a={names[0]}&b={names[1]}")
    expect(page.locator("#compare-figures[data-shown]")).to_have_count(1, timeout=60_000)
    drawn = page.evaluate(
        """() => [...document.querySelectorAll('#compare-figures .compare-figure')].map(
            (box) => box.data.map((trace) => ({name: trace.name, y: trace.y, runs: trace.text})))"""
    )
    tested = expected.changes[
        expected.changes["q_value"].notna() & (expected.changes["measure"] != "run duration")
    ]
    assert len(drawn) == min(6, 1 + len(tested))
    assert all([trace["name"] for trace in figure] == ["A", "B"] for figure in drawn)
    for log, trace in zip((calm, full), drawn[0], strict=True):
        times = log.groupby(log[CASE].astype(str))["time:timestamp"]
        spans = (times.max() - times.min()).dt.total_seconds()
        got = dict(zip(trace["runs"], trace["y"], strict=True))
        assert sorted(got) == sorted(spans.index)
        for run, seconds in spans.items():
            assert got[run] == pytest.approx(seconds, abs=1e-3)


def test_a_figure_names_its_unit(tmp_path):
    """The y axis of a measure's figure: counts per run for a frequency and for resends,
    seconds for a duration or a wait, metres for a distance or an area, the measure itself
    for a share."""
    from robotale.eventlog.readers import read_log
    from robotale.webapp.views.compare import _figure

    full = read_log(mission.write_injected("robotale.csv", tmp_path / "mission.csv"))
    calm = full[~full[CASE].isin(mission.REFILL_RUNS)].reset_index(drop=True)
    values = compare_logs(calm, full).per_run
    for measure, unit in (
        ("activity frequency", "times per run"),
        ("transition frequency", "times per run"),
        ("message resends", "times per run"),
        ("activity duration", "seconds"),
        ("transition wait", "seconds"),
        ("message loss", "message loss"),
    ):
        first = values[values["measure"] == measure].iloc[0]
        key = ["measure", "subject", "who"]
        mine = values[(values[key] == first[key]).all(axis=1)]
        figure = _figure(measure, first["subject"], first["who"], mine, ("A", "B"))
        assert figure["layout"]["yaxis"]["title"]["text"] == unit, measure
    # where the robots worked (this mission has no positions: two runs written here)
    for measure, unit in (
        ("distance travelled", "metres per run"),
        ("region area", "square metres"),
        ("encounters", "times per run"),
    ):
        mine = pd.DataFrame({"run": ["r1", "r2"], "value": [1.0, 2.0], "side": [0, 1]})
        figure = _figure(measure, "distance", "Tractor", mine, ("A", "B"))
        assert figure["layout"]["yaxis"]["title"]["text"] == unit, measure
