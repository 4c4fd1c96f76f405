"""Every figure of the performance, communication and battery perspectives of the mission with
injected findings (``tests/mission_findings.py``), against the same figure computed here with
pandas (and scipy for the confidence figure) from the mission's truth, in the conventions that
carry it.

The waits are checked on robotale's CSV, whose instant events are marked as such: the other
conventions write an instant as a lone completion, whose start (and the wait before it) the
log does not have. The battery is checked on the conventions with in-progress samples.
"""

from __future__ import annotations

import math

import mission_findings as mission
import numpy as np
import pandas as pd
import pytest
from scipy.stats import mannwhitneyu

from robotale.enhancement.battery import IDLE, battery_perspective
from robotale.enhancement.communication import communication_perspective
from robotale.enhancement.performance import performance_perspective
from robotale.eventlog.readers import read_log

TRUTH = mission.injected_truth()
ARROW = " -> "


@pytest.fixture(scope="module")
def logs(tmp_path_factory):
    folder = tmp_path_factory.mktemp("logs")
    return {name: read_log(mission.write_injected(name, folder / name)) for name in mission.WRITERS}


def _table(perspective, name: str) -> pd.DataFrame:
    return pd.DataFrame(perspective.tables[name])


def _instances() -> pd.DataFrame:
    return TRUTH.instance_table()


def _durations() -> pd.Series:
    spans = _instances().groupby("case").agg(first=("start", "min"), last=("end", "max"))
    return (spans["last"] - spans["first"]).dt.total_seconds()


def _steps(instants_start: bool = True) -> pd.DataFrame:
    """Each robot's consecutive instances in a case and its idle time between them: from the
    latest completion so far to the next start. Without ``instants_start`` the log writes an
    instant event as a lone completion, so the time before one is no known wait."""
    rows = []
    for (case, robot), own in _instances().groupby(["case", "robot"]):
        own = own.sort_values("start", kind="stable")
        busy = own["end"].cummax()
        for k in range(len(own) - 1):
            source, target = own.iloc[k], own.iloc[k + 1]
            if not instants_start and target["start"] == target["end"]:
                continue
            wait = max((target["start"] - busy.iloc[k]).total_seconds(), 0.0)
            rows.append((case, robot, source["activity"], target["activity"], busy.iloc[k]))
            rows[-1] += (target["start"], wait)
    columns = ["case", "robot", "source", "target", "source_end", "target_start", "wait"]
    return pd.DataFrame(rows, columns=columns)


def _busy(own: pd.DataFrame) -> float:
    """Seconds covered by the union of a robot's instances."""
    total, reach = 0.0, None
    for start, end in own.sort_values("start")[["start", "end"]].itertuples(index=False):
        if reach is None or start > reach:
            total, reach = total + (end - start).total_seconds(), end
        elif end > reach:
            total, reach = total + (end - reach).total_seconds(), end
    return total


def _approx_rows(found: pd.DataFrame, expected: pd.DataFrame, keys: list[str]) -> None:
    found = found.set_index(keys).sort_index()
    expected = expected.set_index(keys).sort_index()
    assert list(found.index) == list(expected.index)
    for column in expected.columns:
        assert found[column].tolist() == pytest.approx(expected[column].tolist(), nan_ok=True), (
            column
        )


# -- performance --------------------------------------------------------------------------------


@pytest.mark.parametrize("convention", list(mission.WRITERS))
def test_activity_durations(logs, convention):
    found = _table(performance_perspective(logs[convention]), "activities")
    grouped = _instances().groupby(["activity", "robot"])["seconds"]
    expected = grouped.agg(["count", "mean", "median", "max", "sum"]).rename(
        columns={"sum": "total"}
    )
    _approx_rows(found, expected.reset_index(), ["activity", "robot"])


def test_runs_robots_working_and_waiting(logs):
    performance = performance_perspective(logs["robotale.csv"])
    table = _instances()
    steps = _steps()
    per_robot = []
    for (case, robot), own in table.groupby(["case", "robot"]):
        span = (own["end"].max() - own["start"].min()).total_seconds()
        waiting = steps.loc[(steps["case"] == case) & (steps["robot"] == robot), "wait"].sum()
        per_robot.append((case, robot, len(own), span, waiting, _busy(own)))
    robots = pd.DataFrame(
        per_robot, columns=["case", "robot", "activities", "span", "waiting", "working"]
    )
    assert (robots["span"] == robots["waiting"] + robots["working"]).all()
    _approx_rows(_table(performance, "robots")[robots.columns], robots, ["case", "robot"])
    cases = robots.groupby("case")[["working", "waiting"]].sum()
    cases["activities"] = table.groupby("case").size()
    cases["robots"] = table.groupby("case")["robot"].nunique()
    cases["duration"] = _durations()
    found = _table(performance, "cases")[["case", *cases.columns]]
    _approx_rows(found, cases.reset_index(), ["case"])
    summary = performance.summary
    durations = _durations()
    assert summary["cases"] == len(durations)
    assert summary["case_duration_mean"] == pytest.approx(durations.mean())
    assert summary["case_duration_median"] == pytest.approx(durations.median())
    working, waiting = robots["working"].sum(), robots["waiting"].sum()
    assert summary["working_time"] == pytest.approx(working)
    assert summary["waiting_time"] == pytest.approx(waiting)
    assert summary["waiting_share"] == pytest.approx(waiting / (working + waiting))


def test_transition_waits_and_the_slowest(logs):
    performance = performance_perspective(logs["robotale.csv"])
    grouped = _steps().groupby(["source", "target", "robot"])["wait"]
    expected = grouped.agg(["count", "mean", "median", "max", "sum"]).rename(
        columns={"sum": "total"}
    )
    found = _table(performance, "waiting")
    _approx_rows(found, expected.reset_index(), ["source", "target", "robot"])
    slowest = expected.reset_index().sort_values(["mean", "count"], ascending=False).iloc[0]
    assert performance.summary["slowest_transition"] == (
        f"{slowest['source']} -> {slowest['target']} ({slowest['robot']})"
    )


def _variant_figures(paths: pd.DataFrame, keys: list[str]) -> pd.DataFrame:
    grouped = paths.groupby(keys)["seconds"]
    table = grouped.agg(["count", "mean", "median", "max"]).rename(columns={"count": "cases"})
    table = table.reset_index()
    total = table.groupby("robot")["cases"].transform("sum") if "robot" in keys else len(paths)
    table["share"] = table["cases"] / total
    table["activities"] = table["variant"].str.count(ARROW) + 1
    return table


@pytest.mark.parametrize("convention", list(mission.WRITERS))
def test_variants_per_run_and_per_robot(logs, convention):
    performance = performance_perspective(logs[convention])
    ordered = _instances().sort_values(["case", "start"], kind="stable")
    runs = ordered.groupby("case")["activity"].agg(ARROW.join).rename("variant").to_frame()
    runs["seconds"] = _durations()
    expected = _variant_figures(runs, ["variant"])
    _approx_rows(_table(performance, "variants")[expected.columns], expected, ["variant"])
    robots = ordered.groupby(["case", "robot"]).agg(
        variant=("activity", ARROW.join), first=("start", "min"), last=("end", "max")
    )
    robots["seconds"] = (robots["last"] - robots["first"]).dt.total_seconds()
    expected_robots = _variant_figures(robots.reset_index(), ["robot", "variant"])
    found = _table(performance, "robot_variants")[expected_robots.columns]
    _approx_rows(found, expected_robots, ["robot", "variant"])
    summary = performance.summary
    assert summary["variants"] == runs["variant"].nunique() == 5
    assert summary["top_variant_cases"] == runs["variant"].value_counts().iloc[0]
    assert summary["robot_variants"] == len(expected_robots)


# -- communication ------------------------------------------------------------------------------


def _messages() -> pd.DataFrame:
    messages = pd.DataFrame([vars(m) for m in TRUTH.messages])
    messages["latency"] = (messages["received"] - messages["sent"]).dt.total_seconds()
    return messages


def _latency_figures(latency: pd.Series) -> dict:
    got = latency.dropna()
    return {
        "latency_mean": got.mean(),
        "latency_median": got.median(),
        "latency_p95": got.quantile(0.95),
        "latency_max": got.max(),
    }


@pytest.mark.parametrize("convention", list(mission.WRITERS))
def test_message_figures_per_type_and_channel(logs, convention):
    communication = communication_perspective(logs[convention])
    messages = _messages()
    lost = messages["received"].isna()
    if convention != "robot_id.csv":  # only msg_receiver names a lost message's receiver
        messages.loc[lost, "receiver"] = "unknown"
    channels = messages.groupby(["sender", "receiver"])
    # delayed: above the channel's own 95th percentile, for channels of 20 received or more
    p95 = channels["latency"].transform(lambda t: t.quantile(0.95) if t.count() >= 20 else math.inf)
    messages["delayed"] = messages["latency"] > p95
    rows = []
    for (sender, receiver), own in messages.groupby(["sender", "receiver"]):
        rows.append(
            {"sender": sender, "receiver": receiver, "sent": len(own)}
            | {"received": own["received"].notna().sum(), "lost": own["received"].isna().sum()}
            | {"delayed": own["delayed"].sum()}
            | _latency_figures(own["latency"])
        )
    expected = pd.DataFrame(rows)
    found = _table(communication, "channels")[expected.columns]
    _approx_rows(found, expected, ["sender", "receiver"])

    kind = _table(communication, "message_types").iloc[0]
    resends = messages["resend_of"].notna().sum()
    expected_type = {
        "sent": len(messages),
        "received": (~lost).sum(),
        "lost": lost.sum(),
        "delayed": messages["delayed"].sum(),
        "resends": resends,
        "resends_same_id": 0,
        "resends_new_id": resends,
        "recovered": messages.loc[messages["resend_of"].notna(), "received"].notna().sum(),
        "receivers_mean": (~lost).mean(),  # one receiver per received message here
        "loss_rate": lost.mean(),
        "channels": len(expected),
    } | _latency_figures(messages["latency"])
    for figure, value in expected_type.items():
        assert kind[figure] == pytest.approx(value), figure
    assert kind["message_type"] == "weed_position!"

    durations = _durations()
    hit = durations.index.isin(messages.loc[lost, "case"])
    summary = communication.summary
    assert summary["lost_cases_longer_by"] == pytest.approx(
        durations[hit].mean() - durations[~hit].mean()
    )
    expected_p = mannwhitneyu(durations[hit], durations[~hit], method="asymptotic").pvalue
    assert summary["lost_cases_p_value"] == pytest.approx(expected_p)
    assert summary["channels"] == len(expected)


# -- battery ------------------------------------------------------------------------------------


def _samples() -> pd.DataFrame:
    return pd.DataFrame([vars(s) for s in TRUTH.samples])


def _level(case: str, robot: str, at: pd.Timestamp, until: pd.Timestamp | None = None) -> float:
    """The robot's last sample at or before ``at``; with ``until``, when there is none, its
    first sample from ``at`` to ``until``."""
    own = _samples()
    own = own[(own["case"] == case) & (own["robot"] == robot)].sort_values("time")
    before = own[own["time"] <= at]
    if not before.empty:
        return float(before["battery"].iloc[-1])
    after = own[(own["time"] >= at) & (own["time"] <= until)] if until is not None else own[:0]
    return float(after["battery"].iloc[0]) if not after.empty else np.nan


@pytest.mark.parametrize("convention", ["robotale.csv", "inprogress.xes"])
def test_battery_use_levels_and_energy(logs, convention):
    battery = battery_perspective(logs[convention])
    samples = _samples()
    levels = _table(battery, "levels")
    assert len(levels) == len(samples)
    assert sorted(levels["battery"]) == sorted(samples["battery"])

    energy = []
    for (case, robot), own in samples.sort_values("time").groupby(["case", "robot"]):
        change = own["battery"].diff()
        energy.append(
            {"case": case, "robot": robot, "first_level": own["battery"].iloc[0]}
            | {"last_level": own["battery"].iloc[-1], "lowest_level": own["battery"].min()}
            | {"used": (-change).clip(lower=0).sum(), "charged": change.clip(lower=0).sum()}
        )
    energy = pd.DataFrame(energy)
    _approx_rows(_table(battery, "energy")[energy.columns], energy, ["case", "robot"])

    table = _instances()
    table["start_level"] = [
        _level(i.case, i.robot, i.start, i.end) for i in table.itertuples(index=False)
    ]
    table["end_level"] = [_level(i.case, i.robot, i.end) for i in table.itertuples(index=False)]
    table = table.dropna(subset=["start_level", "end_level"])
    table["used"] = (table["start_level"] - table["end_level"]).clip(lower=0)  # never < 0
    work = table.groupby(["activity", "robot"]).agg(
        instances=("used", "size"),
        used=("used", "sum"),
        seconds=("seconds", "sum"),
        start_level_mean=("start_level", "mean"),
        start_level_min=("start_level", "min"),
    )
    steps = _steps(instants_start=convention == "robotale.csv")
    steps = steps[steps["wait"] > 0]
    steps["from"] = [
        _level(s.case, s.robot, s.source_end, s.target_start) for s in steps.itertuples()
    ]
    steps["to"] = [_level(s.case, s.robot, s.target_start) for s in steps.itertuples()]
    steps = steps.dropna(subset=["from", "to"])
    idle = (
        steps.assign(used=(steps["from"] - steps["to"]).clip(lower=0))
        .groupby("robot")
        .agg(instances=("used", "size"), used=("used", "sum"), seconds=("wait", "sum"))
        .assign(activity=IDLE)
        .reset_index()
    )
    expected = pd.concat([work.reset_index(), idle], ignore_index=True)
    expected["used_per_instance"] = expected["used"] / expected["instances"]
    minutes = (expected["seconds"] / 60).where(expected["seconds"] > 0)
    expected["used_per_minute"] = expected["used"] / minutes
    found = _table(battery, "consumption")[expected.columns]
    _approx_rows(found, expected, ["activity", "robot"])

    summary = battery.summary
    # per robot, never a sum over robots: each robot's mean use over its runs
    per_run = energy.groupby("robot")["used"].mean()
    assert summary["used_per_run"] == pytest.approx(per_run.to_dict())
    waiting = idle.set_index("robot")["used"]
    assert summary["used_while_waiting"] == pytest.approx(waiting.to_dict())
    assert summary["most_used_by"] == work["used"].idxmax()[0]
    # the energy of a run is what its activities and waits used: nothing goes uncounted
    assert work["used"].sum() + idle["used"].sum() == pytest.approx(energy["used"].sum())

    lows = _table(battery, "low_battery")
    expected_lows = table[table["activity"] == "low_battery"]
    assert sorted(lows["case"]) == sorted(mission.LOW_BATTERY_RUNS)
    for low in expected_lows.itertuples():
        mine = _instances()
        mine = mine[(mine["case"] == low.case) & (mine["robot"] == low.robot)]
        after = mine[mine["start"] > low.start].sort_values("start")["activity"].head(3)
        row = lows[lows["case"] == low.case].iloc[0]
        assert row["then"] == ARROW.join(after)
