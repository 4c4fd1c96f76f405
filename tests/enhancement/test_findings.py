"""Every sentence of the findings report checked against counts made here with pandas, on a
mission with injected findings (``tests/mission_findings.py``) written in three conventions,
and on the thesis' real log split into its days."""

from __future__ import annotations

import json

import mission_findings as mission
import pandas as pd
import pytest
from conventions import busy_seconds

from robotale.enhancement.findings import find, robot_areas, seconds_text
from robotale.enhancement.findings_report import (
    findings_dict,
    findings_html,
    findings_text,
    timelines_of,
)
from robotale.eventlog.readers import read_log

TRUTH = mission.injected_truth()


@pytest.fixture(scope="module", params=list(mission.WRITERS))
def logged(request, tmp_path_factory):
    path = mission.write_injected(request.param, tmp_path_factory.mktemp("log") / request.param)
    log = read_log(path)
    return log, find(log)


def _instances() -> pd.DataFrame:
    return TRUTH.instance_table()


def _durations() -> pd.Series:
    spans = _instances().groupby("case").agg(first=("start", "min"), last=("end", "max"))
    return (spans["last"] - spans["first"]).dt.total_seconds()


def _variants() -> pd.Series:
    """Per run, its activities in start order (no two start at once in this mission)."""
    ordered = _instances().sort_values(["case", "start"])
    return ordered.groupby("case")["activity"].agg(" -> ".join)


def test_sequence(logged):
    _, findings = logged
    answer = findings.answer("sequence")
    counts = _variants().value_counts()
    runs = len(mission.RUNS)
    assert answer.facts["runs"] == runs
    assert answer.facts["variants"] == len(counts)
    assert answer.facts["main"][0]["runs"] == counts.iloc[0]
    assert answer.facts["main"][0]["variant"] == counts.index[0]
    assert answer.sentences[0].startswith(f"{runs} runs follow {len(counts)} variants")
    assert f"({counts.iloc[0]} of {runs}," in answer.sentences[0]
    # the runs with the refill are the most common variant; the others differ by not having it
    refill_runs = _variants()[sorted(mission.REFILL_RUNS)]
    assert refill_runs.nunique() == 1 and counts.index[0] == refill_runs.iloc[0]
    assert f"without {mission.REFILL}" in answer.sentences[1]


def test_the_injected_bottleneck_comes_first(logged):
    _, findings = logged
    answer = findings.answer("delays")
    first = answer.facts["bottlenecks"][0]
    assert (first["activity"], first["robot"]) == (mission.REFILL, "tractor_1")
    assert first["runs"] == len(mission.REFILL_RUNS)
    assert mission.REFILL in answer.sentences[0] and "tractor_1" in answer.sentences[0]
    node = answer.evidence[0]
    assert (node["kind"], node["activity"], node["robot"]) == ("node", mission.REFILL, "tractor_1")
    durations = _durations()
    slowest = next(e for e in answer.evidence if e["kind"] == "timeline")
    assert slowest["case"] == durations.idxmax()
    assert slowest["case"] in mission.REFILL_RUNS


def test_where_each_robot_worked(logged):
    _, findings = logged
    answer = findings.answer("robots")
    table = _instances()
    working = table.groupby(["case", "robot"]).apply(busy_seconds).groupby("robot").sum()
    main = table.groupby(["robot", "activity"])["seconds"].sum().groupby("robot").idxmax()
    facts = {r["robot"]: r for r in answer.facts["robots"]}
    assert set(facts) == set(TRUTH.robots)
    for robot, sentence in zip(sorted(TRUTH.robots), answer.sentences, strict=False):
        assert facts[robot]["working"] == pytest.approx(working[robot])
        assert facts[robot]["runs"] == table.loc[table["robot"] == robot, "case"].nunique()
        assert facts[robot]["main_activity"] == main[robot][1]
        assert sentence.startswith(f"{robot} worked {seconds_text(working[robot])}")
        assert sentence.endswith(f"most of it on {main[robot][1]}.")
    assert answer.sentences[-1] == "The log has no positions, so where robots overlap is unknown."


def test_battery(logged):
    _, findings = logged
    answer = findings.answer("battery")
    table = _instances()
    lows = table[table["activity"] == "low_battery"]
    assert set(lows["case"]) == mission.LOW_BATTERY_RUNS
    assert answer.facts["low_battery_events"] == len(lows)
    assert answer.facts["runs_with_low_battery"] == lows["case"].nunique()
    durations = _durations()
    hit = durations[durations.index.isin(lows["case"])]
    calm = durations[~durations.index.isin(lows["case"])]
    longer = hit.median() - calm.median()
    assert longer == pytest.approx(mission.RECHARGE_SECONDS)
    assert answer.facts["longer_by"] == pytest.approx(longer)
    runs = len(mission.RUNS)
    assert f"{len(lows)} low-battery moments in {lows['case'].nunique()} of {runs} runs" in (
        " ".join(answer.sentences)
    )
    assert f"took {seconds_text(longer)} longer" in answer.sentences[-1]


def test_messages(logged):
    _, findings = logged
    answer = findings.answer("messages")
    messages = pd.DataFrame([m.__dict__ for m in TRUTH.messages])
    lost = messages[messages["received"].isna()]
    resent = messages[messages["resend_of"].notna()]
    latency = (messages["received"] - messages["sent"]).dt.total_seconds()
    # a message that took more than twice its channel's usual (median) time
    usual = latency.groupby(messages["receiver"]).transform("median")
    delayed = messages[latency > 2 * usual]
    assert answer.facts["messages"] == len(messages)
    assert answer.facts["received"] == messages["received"].notna().sum()
    assert answer.facts["lost"] == len(lost)
    assert answer.facts["delayed"] == len(delayed) == 1
    assert answer.facts["resends_new_id"] == len(resent)
    first = answer.sentences[0]
    assert first.startswith(f"{len(messages)} messages sent: {messages['received'].notna().sum()}")
    assert f"{len(lost)} lost, {len(delayed)} delayed" in first
    examples = {s.split(",")[0]: s for s in answer.sentences[1:]}
    # every message type is receive-tagged in this mission; the delay rule is stated
    assert answer.facts["untagged_types"] == [] and answer.facts["unobserved"] == 0
    assert any(s.startswith("Delayed means a latency in the slow mode") for s in answer.sentences)
    delayed_row = delayed.iloc[0]
    assert delayed_row["msg_id"] in examples["Delayed"]
    assert f"after {seconds_text(mission.DELAYED_LATENCY)}" in examples["Delayed"]
    first_lost = lost.sort_values("case").iloc[0]
    assert first_lost["msg_id"] in examples["Lost"]
    durations = _durations()
    calm = durations[~durations.index.isin(lost["case"])].median()
    shorter = calm - durations[first_lost["case"]]  # the refill runs make the calm ones long
    assert shorter > 0
    assert examples["Lost"].endswith(
        f"; its run took {seconds_text(shorter)} shorter than the median run without one."
    )
    first_resent = resent.sort_values("case").iloc[0]
    assert examples["Resent"].startswith(f"Resent, for example: {first_resent['msg_id']} ")
    assert f"repeats {first_resent['resend_of']}, which had no answer" in examples["Resent"]
    cases = [e["case"] for e in answer.evidence]
    assert cases == [delayed_row["case"], first_lost["case"], first_lost["case"]]


def test_report_outputs_carry_the_same_sentences(logged):
    log, findings = logged
    timelines = timelines_of(findings, log)
    data = findings_dict(findings, timelines, "t")
    json.dumps(data)
    text = findings_text(findings)
    page = findings_html(findings, timelines, "t")
    for answer in data["answers"]:
        for sentence in answer["sentences"]:
            assert sentence in text
    timelines = {t["case"]: t for t in data["timelines"]}
    lost_run = sorted(mission.LOST_RUNS)[0]
    assert timelines[lost_run]["lost"] == 1
    assert page.count("id='timeline-") == len(timelines)
    assert "lost message" in page


def test_areas_against_pandas():
    log = pd.DataFrame(
        {
            "robot": ["a", "a", "b", "b", "c", "c"],
            "x": [0.0, 4.0, 3.0, 6.0, 8.0, 9.0],
            "y": [0.0, 2.0, 1.0, 5.0, 8.0, 9.0],
        }
    )
    boxes = log.groupby("robot").agg(["min", "max"])
    areas = robot_areas(log)
    for robot in "abc":
        assert areas[robot]["x"] == [boxes.loc[robot, ("x", "min")], boxes.loc[robot, ("x", "max")]]
        assert "z" not in areas[robot]


def test_thesis_log_split_into_days(thesis_csv):
    """The thesis' five days: the night between them is no delay of any run."""
    log = read_log(thesis_csv, case_gap="1h")
    findings = find(log)
    days = log["time:timestamp"].dt.date.nunique()
    sequence = findings.answer("sequence")
    assert sequence.facts["runs"] == days
    longest_day = (
        log.groupby("case:concept:name")["time:timestamp"].agg(lambda t: t.max() - t.min()).max()
    )
    for bottleneck in findings.answer("delays").facts["bottlenecks"]:
        assert bottleneck["delay_per_case"] < longest_day.total_seconds()
    messages = findings.answer("messages")
    sends = log[log["concept:name"].astype(str).str.endswith("!")]
    assert messages.facts["messages"] == sends["msg_id"].nunique()
    assert "one_run_days" not in findings.answer("delays").facts


def test_thesis_log_read_as_one_run_says_its_nights_count_as_waiting(thesis_csv):
    """Without a case gap the five days are one run: the delays answer says so first."""
    times = pd.to_datetime(pd.read_csv(thesis_csv)["time"], format="ISO8601")
    days = (times.max().normalize() - times.min().normalize()).days + 1
    delays = find(read_log(thesis_csv)).answer("delays")
    assert delays.facts["one_run_days"] == days == 5
    assert delays.sentences[0].startswith(
        f"The log is one run of {days} days ({times.min():%Y-%m-%d} to {times.max():%Y-%m-%d})"
    )
    assert "--case-gap 1h" in delays.sentences[0]
    assert delays.sentences[1].startswith("1. ")


def test_a_log_without_a_robot_column(thesis_csv):
    """Without robots the answers say so, and the messages are still counted: the thesis'
    lost messages are the ids sent ('!') and never received ('?')."""
    log = read_log(thesis_csv, case_gap="1h").drop(columns=["robot"])
    findings = find(log)
    assert findings.answer("robots").sentences == [
        "The log does not say which robot did what (no robot column)."
    ]
    ids = log.dropna(subset=["msg_id"])
    sent = set(ids.loc[ids["concept:name"].str.endswith("!"), "msg_id"])
    received = set(ids.loc[ids["concept:name"].str.endswith("?"), "msg_id"])
    assert findings.answer("messages").facts["lost"] == len(sent - received) > 0
    # tagged low-battery moments but no levels: their markers and no level lines
    assert [trace.name for trace in findings.perspectives["battery"].figure.data] == ["low battery"]
