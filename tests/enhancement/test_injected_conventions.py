"""The perspectives of the mission with injected findings (``tests/mission_findings.py``) give the
same, right answers in four conventions: robotale's CSV, an XES whose starts say
``state=inprogress`` (``execution_id`` pairing, ``null`` markers), a CSV with ``robot_id`` +
``org:resource`` and senders/receivers (resends under new ids), and the thesis' CSV (no case
column: its runs, hours apart, are told apart by ``--case-gap 1h``).

Every expected figure is counted here from the mission's truth with pandas (and scipy's
Mann-Whitney U for the confidence figure), never by the code under test.
"""

from __future__ import annotations

import conventions
import mission_findings as mission
import pandas as pd
import pytest
from scipy.stats import mannwhitneyu

from robotale.enhancement.bottlenecks import EFFECTS, find_bottlenecks
from robotale.enhancement.communication import communication_perspective
from robotale.enhancement.performance import performance_perspective
from robotale.eventlog import schema
from robotale.eventlog.readers import read_log_with_reading

WRITERS = {**mission.WRITERS, "thesis.csv": conventions.write_thesis_csv}
TRUTH = mission.injected_truth()


@pytest.fixture(scope="module", params=list(WRITERS))
def injected(request, tmp_path_factory):
    """(convention, log, reading, the log's case -> the truth's run)."""
    path = tmp_path_factory.mktemp("log") / request.param
    with mission.run_starts():
        WRITERS[request.param](TRUTH, path)
    gap = "1h" if request.param == "thesis.csv" else None
    log, reading = read_log_with_reading(path, case_gap=gap)
    return request.param, log, reading, _runs_of(log)


def _runs_of(log: pd.DataFrame) -> dict[str, str]:
    """Each case of the log named by the truth's run that begins when it begins."""
    firsts = log.groupby(schema.CASE)[schema.TIMESTAMP].min()
    starts = {pd.Timestamp(start): run for run, start in mission.STARTS.items()}
    return {str(case): starts[time] for case, time in firsts.items()}


def _durations() -> pd.Series:
    table = TRUTH.instance_table()
    spans = table.groupby("case").agg(first=("start", "min"), last=("end", "max"))
    return (spans["last"] - spans["first"]).dt.total_seconds()


def test_every_run_lasts_what_it_lasted(injected):
    _, log, _, runs = injected
    cases = performance_perspective(log).tables["cases"]
    found = pd.Series(cases["duration"].to_numpy(), index=cases["case"].astype(str).map(runs))
    expected = _durations()
    assert sorted(found.index) == sorted(expected.index) == mission.RUNS
    assert found.sort_index().tolist() == pytest.approx(expected.sort_index().tolist())


def test_the_optional_waiting_activity_ranks_first_by_its_effect(injected):
    _, log, _, _ = injected
    ranking = find_bottlenecks(log).table
    first = ranking.iloc[0]
    assert (first["kind"], first["activity"], first["robot"]) == (
        "activity",
        mission.REFILL,
        "tractor_1",
    )
    durations = _durations()
    has = durations.index.isin(sorted(mission.REFILL_RUNS))
    with_it, without = durations[has], durations[~has]
    assert (first["cases"], first["cases_without"]) == (len(with_it), len(without)) == (4, 8)
    assert first["longer_by"] == pytest.approx(with_it.mean() - without.mean())
    assert first["extra_median"] == pytest.approx(with_it.median() - without.median())
    assert first["delay_per_case"] == pytest.approx(
        (with_it.mean() - without.mean()) * len(with_it) / len(durations)
    )
    expected_p = mannwhitneyu(with_it, without, method="asymptotic").pvalue
    assert first["p_value"] == pytest.approx(expected_p)
    assert first["longer_by"] == pytest.approx(mission.REFILL_SECONDS - 24)  # 380 s against 104
    # tractor_2's wait is in every run: its name says it waits, but it has no effect to measure
    effects = ranking[ranking["kind"].isin(EFFECTS)]
    assert not ((effects["activity"] == "wait") & (effects["robot"] == "tractor_2")).any()
    # every row the runs do not show for certain (p of 0.05 or more, no test result, or under
    # 1 % of the runs' time) comes after every row they do
    total = durations.sum()
    sure = ranking["p_value"].lt(0.05) & (ranking["total"] / total).ge(0.01)
    assert ranking["ranked"].tolist() == sure.tolist()
    unsure = list(~sure)
    assert unsure == sorted(unsure)


def _truth_messages() -> pd.DataFrame:
    return pd.DataFrame([vars(m) for m in TRUTH.messages])


def test_channels_resends_and_losses(injected):
    convention, log, _, _ = injected
    perspective = communication_perspective(log)
    truth = _truth_messages()
    summary = perspective.summary
    assert summary["messages"] == len(truth)
    assert summary["lost"] == truth["received"].isna().sum() == len(mission.LOST_RUNS)
    assert summary["resends_new_id"] == truth["resend_of"].notna().sum()
    assert summary["resends_same_id"] == 0
    assert summary["recovered"] == truth["resend_of"].notna().sum()
    channels = perspective.tables["channels"].set_index(["sender", "receiver"])
    if convention != "robot_id.csv":
        # only msg_receiver names the robot a lost message was meant for; else it is unknown
        truth.loc[truth["received"].isna(), "receiver"] = "unknown"
    expected = truth.groupby(["sender", "receiver"]).agg(
        sent=("msg_id", "size"), received=("received", "count")
    )
    expected["lost"] = expected["sent"] - expected["received"]
    assert sorted(channels.index) == sorted(expected.index)
    for channel, counts in expected.iterrows():
        for figure in ("sent", "received", "lost"):
            assert channels.loc[channel, figure] == counts[figure]
    # the delayed message: above its channel's own 95th percentile
    delayed = perspective.tables["messages"]
    assert delayed.loc[delayed["delayed"], "msg_id"].tolist() == [f"{mission.DELAYED_RUN}-m2"]


def test_what_followed_a_lost_message_and_how_much_later_its_run_ended(injected):
    _, log, _, runs = injected
    lost = communication_perspective(log).tables["lost"]
    truth = _truth_messages()
    gone = truth[truth["received"].isna()]
    assert sorted(lost["msg_id"]) == sorted(gone["msg_id"])
    table = TRUTH.instance_table()
    durations = _durations()
    calm = durations[~durations.index.isin(gone["case"])].median()
    for message in gone.itertuples():
        row = lost[lost["msg_id"] == message.msg_id].iloc[0]
        assert runs[str(row["case"])] == message.case
        mine = table[(table["case"] == message.case) & (table["robot"] == message.sender)]
        after = mine[mine["start"] > message.sent].sort_values("start")["activity"].head(3)
        assert row["then"] == " -> ".join(after)
        assert row["resent_as"] == truth.loc[truth["resend_of"] == message.msg_id, "msg_id"].item()
        assert row["until_end"] == pytest.approx(
            (table.loc[table["case"] == message.case, "end"].max() - message.sent).total_seconds()
        )
        assert row["ended_later_by"] == pytest.approx(durations[message.case] - calm)


def test_robot_types_and_nothing_dropped(injected):
    convention, _, reading, _ = injected
    events = [e for e in TRUTH.events()]
    samples = sum(e["lifecycle"] == "sample" for e in events)
    written = len(events) - (0 if convention in ("robotale.csv", "inprogress.xes") else samples)
    assert reading.rows == reading.kept == written and not reading.dropped
    assert reading.cases == len(mission.RUNS)
    if convention == "thesis.csv":  # the thesis' CSV names no robot types
        assert reading.robots == dict.fromkeys(sorted(TRUTH.robots))
    else:
        assert reading.robots == TRUTH.robots
    instants = sum(i.instant for i in TRUTH.instances)
    spans = len(TRUTH.instances) - instants
    assert reading.events["start"] == spans
    # the thesis' recorder writes an instant event as a lone completion
    assert reading.events["complete"] + reading.events["instant"] == spans + instants
