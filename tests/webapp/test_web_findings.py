"""The Findings, Timeline, Perspectives and Model pages on a mission with injected findings
(``tests/mission_findings.py``), in a real Neo4j and a real headless Chromium; every expected
figure is counted here from the mission's truth with pandas."""

from __future__ import annotations

import uuid

import mission_findings as mission
import pandas as pd
import pytest
from playwright.sync_api import expect

TRUTH = mission.injected_truth()
#: robots no stored model has a pool for
STRANGERS = {"drone": "walker_1", "tractor_1": "crane_a", "tractor_2": "crane_b"}


def _store(driver, log: pd.DataFrame, prefix: str) -> str:
    from robotale.ekg.build import build_ekg
    from robotale.ekg.keys import built_keys

    name = f"{prefix}_{uuid.uuid4().hex[:8]}"
    entities = ["robot", "msg_id"]
    build_ekg(driver, log, name, entities=entities, aggregate=built_keys(entities), progress=False)
    return name


@pytest.fixture(scope="module")
def mission_log(neo4j_driver, tmp_path_factory):
    """The injected mission as robotale's CSV, stored once for this module."""
    from robotale.ekg.logs import delete_log
    from robotale.eventlog.readers import read_log

    path = mission.write_injected("robotale.csv", tmp_path_factory.mktemp("m") / "mission.csv")
    name = _store(neo4j_driver, read_log(path), "test_findings")
    yield name
    delete_log(neo4j_driver, name)


@pytest.fixture(scope="module")
def stranger_log(neo4j_driver, tmp_path_factory):
    """The same mission without battery data, by robots no shipped model binds."""
    from robotale.ekg.logs import delete_log
    from robotale.eventlog.readers import read_log

    path = mission.write_injected("robotale.csv", tmp_path_factory.mktemp("s") / "mission.csv")
    log = read_log(path).drop(columns=["battery"])
    # the samples carried the levels; the low-battery moments are battery data too
    log = log[log["lifecycle:state"].astype(str) != "inprogress"]
    log = log[log["concept:name"] != "low_battery"]
    log["robot"] = log["robot"].map(STRANGERS)
    name = _store(neo4j_driver, log.reset_index(drop=True), "test_strangers")
    yield name
    delete_log(neo4j_driver, name)


def _lost_by_run() -> pd.Series:
    messages = pd.DataFrame([m.__dict__ for m in TRUTH.messages])
    return messages[messages["received"].isna()].groupby("case").size()


# -- the JSON the pages draw ------------------------------------------------------------------


def test_findings_api_names_the_injected_findings(client, mission_log):
    data = client.get(f"/api/findings?log={mission_log}").json
    answers = {a["key"]: a for a in data["answers"]}
    first = answers["delays"]["facts"]["bottlenecks"][0]
    assert (first["activity"], first["robot"]) == (mission.REFILL, "tractor_1")
    spans = TRUTH.instance_table().groupby("case").agg(first=("start", "min"))
    assert [run["case"] for run in data["runs"]] == spans.sort_values("first").index.tolist()
    lost = _lost_by_run()
    assert answers["messages"]["facts"]["lost"] == lost.sum()


def test_findings_and_communication_take_a_delay_threshold(client, mission_log):
    """The truth's latencies: 1.5 s to tractor_1, 2.5 s to tractor_2, one of 30 s. Above 2 s:
    every delivery to tractor_2 and the 30 s one; the default rule finds the 30 s one only."""
    messages = pd.DataFrame([m.__dict__ for m in TRUTH.messages])
    latency = (messages["received"] - messages["sent"]).dt.total_seconds()
    data = client.get(f"/api/findings?log={mission_log}&delay=2").json
    facts = {a["key"]: a for a in data["answers"]}["messages"]["facts"]
    assert facts["delayed"] == int((latency > 2).sum())
    assert facts["delay_rule"] == "a latency above 2 s (the threshold given)"
    default = client.get(f"/api/findings?log={mission_log}").json
    facts = {a["key"]: a for a in default["answers"]}["messages"]["facts"]
    assert facts["delayed"] == int((latency == mission.DELAYED_LATENCY).sum()) == 1
    part = client.get(f"/api/perspectives/communication?log={mission_log}&delay=2").json
    assert part["summary"]["delayed"] == int((latency > 2).sum())
    bad = client.get(f"/api/findings?log={mission_log}&delay=soon")
    assert bad.status_code == 400
    assert bad.json["error"] == "the delay 'soon' is not a number of seconds of 0 or more."


def test_timeline_api_has_the_lost_message(client, mission_log):
    run = sorted(mission.LOST_RUNS)[0]
    data = client.get(f"/api/timeline?log={mission_log}&case={run}").json
    table = TRUTH.instance_table()
    assert data["bars"] == (table["case"] == run).sum()
    assert data["lost"] == _lost_by_run()[run] == 1
    assert data["robots"] == sorted(TRUTH.robots)
    lost_trace = next(t for t in data["figure"]["data"] if t["name"] == "lost message")
    assert len(lost_trace["text"]) == 1
    missing = client.get(f"/api/timeline?log={mission_log}&case=nope")
    assert missing.status_code == 400 and "no run 'nope'" in missing.json["error"]


# -- in Chromium -------------------------------------------------------------------------------

browser = pytest.mark.browser


@browser
def test_findings_page_names_the_injected_bottleneck_first(page, mission_log, screenshot):
    page.goto(f"{page.base_url}/findings?log={mission_log}")
    delays = page.locator("article.answer[data-key=delays]")
    first = delays.locator("li").first
    expect(first).to_contain_text(f"{mission.REFILL} by tractor_1")
    assert first.inner_text().startswith("1.")
    node = delays.locator("a.node-link").first
    target = f"/perspectives?log={mission_log}&activity={mission.REFILL}&robot=tractor_1"
    expect(node).to_have_attribute("href", target)
    messages = page.locator("article.answer[data-key=messages]")
    expect(messages.locator("li").first).to_contain_text(f"{_lost_by_run().sum()} lost")
    screenshot(page, "findings")
    run = sorted(mission.LOST_RUNS)[0]
    messages.locator("a.timeline-link", has_text="lost").click()
    expect(page.locator("#timeline")).to_have_attribute("data-state", "shown")
    expect(page.locator("#timeline")).to_have_attribute("data-case", run)


@browser
def test_timeline_shows_the_lost_message(page, mission_log, screenshot):
    run = sorted(mission.LOST_RUNS)[0]
    page.goto(f"{page.base_url}/timeline?log={mission_log}&case={run}")
    box = page.locator("#timeline")
    expect(box).to_have_attribute("data-state", "shown")
    expect(box).to_have_attribute("data-lost", str(_lost_by_run()[run]))
    expect(page.locator("#timeline-status")).to_contain_text("1 lost")
    expect(box.locator(".legendtext", has_text="lost message")).to_be_visible()
    # the cross is drawn: plotly's point of the lost-message trace
    drawn = page.evaluate(
        "() => document.getElementById('timeline').data"
        ".filter(t => t.name === 'lost message')[0].x.length"
    )
    assert drawn == 1
    screenshot(page, "timeline")
    page.select_option("#run-picker", "run01")
    expect(box).to_have_attribute("data-case", "run01")
    expect(box).to_have_attribute("data-lost", "0")


@browser
def test_timeline_draws_battery_on_its_own_axis_one_colour_per_activity(page, mission_log):
    """In the drawn page: the battery axis lies below the lanes (pixels apart), and each
    activity has its own colour, the one its name's place among the log's activities (in
    text order) picks from the palette."""
    from robotale.enhancement.colours import PALETTE

    run = sorted(mission.LOW_BATTERY_RUNS)[0]
    page.goto(f"{page.base_url}/timeline?log={mission_log}&case={run}")
    expect(page.locator("#timeline")).to_have_attribute("data-state", "shown")
    drawn = page.evaluate(
        """() => {
          const el = document.getElementById('timeline');
          const lanes = el._fullLayout.yaxis, battery = el._fullLayout.yaxis2;
          return {
            lanes: [lanes._offset, lanes._offset + lanes._length],
            battery: [battery._offset, battery._offset + battery._length],
            levels: el.data.filter(t => t.name.startsWith('battery ')).map(t => t.yaxis),
            colours: Object.fromEntries(
              el.data.filter(t => t.type === 'bar').map(t => [t.name, t.marker.color])),
          };
        }"""
    )
    assert drawn["battery"][0] > drawn["lanes"][1]  # pixels from the top: below the lanes
    assert drawn["levels"] and set(drawn["levels"]) == {"y2"}
    names = sorted({i.activity for i in TRUTH.instances})
    expected = {name: PALETTE[n % len(PALETTE)] for n, name in enumerate(names)}
    assert drawn["colours"] == {name: expected[name] for name in drawn["colours"]}
    assert len(set(drawn["colours"].values())) == len(drawn["colours"]) >= 5


@browser
def test_perspectives_page_ranks_bottlenecks_and_shows_variants(page, mission_log):
    page.goto(f"{page.base_url}/perspectives?log={mission_log}")
    bottlenecks = page.locator("article.perspective[data-name=bottlenecks]")
    expect(bottlenecks).to_have_attribute("data-state", "shown")
    expect(bottlenecks.locator("ol.ranking li").first).to_contain_text(
        f"{mission.REFILL} by tractor_1"
    )
    performance = page.locator("article.perspective[data-name=performance]")
    expect(performance).to_have_attribute("data-state", "shown")
    variants = TRUTH.instance_table().sort_values(["case", "start"])
    count = variants.groupby("case")["activity"].agg(" -> ".join).nunique()
    expect(performance.locator(".highlights tbody tr")).to_have_count(min(count, 10))


@browser
def test_a_log_without_battery_or_model_says_so(page, stranger_log):
    page.goto(f"{page.base_url}/perspectives?log={stranger_log}")
    battery = page.locator("article.perspective[data-name=battery]")
    expect(battery).to_have_attribute("data-state", "empty")
    expect(battery.locator(".summary")).to_have_text(
        "The log has no battery levels and no low-battery events."
    )
    expect(battery.locator(".figures > *")).to_have_count(0)
    page.goto(f"{page.base_url}/findings?log={stranger_log}")
    answer = page.locator("article.answer[data-key=battery] li")
    expect(answer).to_have_text(["The log has no battery levels and no low-battery events."])
    page.goto(f"{page.base_url}/model?log={stranger_log}")
    robots = ", ".join(sorted(STRANGERS.values()))
    expect(page.locator("#model-none")).to_contain_text("No stored model has pools that bind")
    expect(page.locator("#model-none")).to_contain_text(robots)
    expect(page.locator("#model-picker option")).to_have_text(["none binds this log"])


def test_the_model_page_offers_only_models_that_bind_the_robots(client, mission_log):
    """The mission's drone and tractors are the pools of the shipped agri mission; the
    rexdingo mission's pools (rex, dingo) bind none of them."""
    import re

    page = client.get(f"/model?log={mission_log}").get_data(as_text=True)
    # the model picker only: the diff's picker beside it lists every stored model
    picker = re.search(r'<select id="model-picker">(.*?)</select>', page, re.S).group(1)
    offered = re.findall(r'<option value="\w+"[^>]*>([^<(]+) \(', picker)
    # other tests may have stored another copy of the agri mission, and the browser tests a
    # collaboration discovered from the thesis log, whose Drone and Tractor pools bind this
    # mission's robots too: each is offered, no other
    names = {name.strip() for name in offered}
    assert "agri.bpmn" in names and names <= {"agri.bpmn", "discovered.bpmn"}
    assert "rexdingo.bpmn" not in picker and "none binds this log" not in picker


# -- the console's analyst questions -----------------------------------------------------------


def _ask(driver, name: str, **parameters) -> pd.DataFrame:
    from robotale.webapp import console

    example = next(e for e in console.examples() if e.name == name)
    result = console.run_read_only(driver, example.text, parameters)[-1]
    return pd.DataFrame(result.rows, columns=result.columns)


def test_the_console_offers_only_the_analysts_questions(client):
    from robotale.webapp import console

    names = [e.name for e in console.examples()]
    assert names == [
        "ask_concurrent_activities",
        "ask_lost_messages",
        "ask_robot_path",
        "ask_slowest_steps",
    ]
    page = client.get("/cypher").get_data(as_text=True)
    assert 'data-name="ekg_delete_log"' not in page and 'data-name="ask_robot_path"' in page


def test_a_robots_path_in_one_run(neo4j_driver, mission_log):
    table = TRUTH.instance_table()
    mine = table[(table["robot"] == "tractor_1") & (table["case"] == "run02")]
    rows = _ask(neo4j_driver, "ask_robot_path", log=mission_log, robot="tractor_1", case="run02")
    assert rows["activity"].tolist() == mine.sort_values("start")["activity"].tolist()


def test_lost_messages_and_what_followed(neo4j_driver, mission_log):
    rows = _ask(neo4j_driver, "ask_lost_messages", log=mission_log, following=2)
    table = TRUTH.instance_table()
    expected = []
    for message in TRUTH.messages:
        if message.received is None:
            later = table[
                (table["case"] == message.case)
                & (table["robot"] == message.sender)
                & (table["start"] > message.sent)
            ]
            expected.append((message.msg_id, later.sort_values("start")["activity"][:2].tolist()))
    assert list(zip(rows["message"], rows["then"], strict=True)) == expected


def test_activities_two_robots_did_at_once(neo4j_driver, mission_log):
    rows = _ask(
        neo4j_driver, "ask_concurrent_activities", log=mission_log, robot="drone", other="tractor_2"
    )
    table = TRUTH.instance_table()
    spans = table[table["seconds"] > 0]
    pairs = spans[spans["robot"] == "drone"].merge(
        spans[spans["robot"] == "tractor_2"], on="case", suffixes=("", "_other")
    )
    begins = pairs[["start", "start_other"]].max(axis=1)
    ends = pairs[["end", "end_other"]].min(axis=1)
    overlapping = pairs[begins < ends]
    seconds = (ends - begins)[begins < ends].dt.total_seconds()
    assert len(rows) == len(overlapping)
    assert sorted(rows["seconds"]) == sorted(seconds.astype(int))
    assert set(zip(rows["activity"], rows["other_activity"], strict=True)) == set(
        zip(overlapping["activity"], overlapping["activity_other"], strict=True)
    )


def test_slowest_steps_stay_within_a_run(neo4j_driver, mission_log):
    rows = _ask(neo4j_driver, "ask_slowest_steps", log=mission_log, top=None, classType=None)
    assert len(rows) == 10
    # the runs are three hours apart: no step between two of them is among the slowest
    assert rows["median_seconds"].max() < 3 * 3600
    first = rows.iloc[0]
    # tractor_1's refill: from its start to its completion, REFILL_SECONDS in every refill run
    assert (first["source"], first["target"]) == (f"{mission.REFILL}|tractor_1",) * 2
    assert first["median_seconds"] == mission.REFILL_SECONDS
    assert first["count"] == len(mission.REFILL_RUNS)
