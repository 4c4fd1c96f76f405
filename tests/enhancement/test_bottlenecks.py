import pytest

from robotale.enhancement import find_bottlenecks
from robotale.enhancement.findings import find


@pytest.fixture
def known_bottleneck(events):
    """20 runs of a robot doing a, b, c, d. b is long work (60 s, always). In runs 0-9 the robot
    waits 100 + 10 i seconds before c; otherwise every wait is half a second. A second robot
    scans for 120 s in every run."""
    rows = []
    for run in range(20):
        t = 0.0
        for activity, duration in (("a", 5), ("b", 60 + (run % 3) * 0.1), ("c", 2), ("d", 3)):
            wait = 100 + 10 * run if activity == "c" and run < 10 else 0.5
            t += wait
            rows.append((run, "r1", activity, "start", t))
            t += duration
            rows.append((run, "r1", activity, "complete", t))
        rows += [(run, "r2", "scan", "start", 0.0), (run, "r2", "scan", "complete", 120.0)]
    return events(
        *[
            {"case": str(c), "robot": r, "activity": a, "lifecycle": lc, "t": t}
            for c, r, a, lc, t in rows
        ]
    )


def test_the_known_bottleneck_comes_first(known_bottleneck):
    ranking = find_bottlenecks(known_bottleneck).table
    first = ranking.iloc[0]
    assert (first["kind"], first["activity"], first["robot"]) == ("waiting", "c", "r1")
    # the excess it costs: all its waiting, averaged over the 20 runs
    waits = [100 + 10 * run for run in range(10)] + [0.5] * 10
    assert first["delay_per_case"] == pytest.approx(sum(waits) / 20)
    # the runs with the long waits take longer than the others, by less than the waits
    # themselves because r2's 120 s scan hides part of r1's time
    times = known_bottleneck.groupby("case:concept:name")["time:timestamp"]
    seconds = (times.max() - times.min()).dt.total_seconds()
    long_runs = seconds.index.astype(int) < 10
    expected = seconds[long_runs].mean() - seconds[~long_runs].mean()
    assert first["longer_by"] == pytest.approx(expected)
    assert 90 < expected < 100
    assert "r1 waits" in first["explanation"] and "before c" in first["explanation"]


def test_long_steady_work_is_not_a_bottleneck(known_bottleneck):
    ranking = find_bottlenecks(known_bottleneck).table
    scan = ranking[ranking["activity"] == "scan"]
    assert scan.empty  # 120 s every time: nothing to gain
    b = ranking[(ranking["activity"] == "b") & (ranking["kind"] == "delay")]
    assert b["delay_per_case"].iloc[0] < 0.1  # 60 s of work, at most 0.2 s above its fastest


def test_resends_are_rework_and_message_latency_is_queueing(events):
    log = events(
        {"case": "1", "robot": "d", "activity": "w!", "lifecycle": "start", "msg_id": "m", "t": 0},
        {
            "case": "1",
            "robot": "d",
            "activity": "w!",
            "lifecycle": "complete",
            "msg_id": "m",
            "t": 1,
        },
        {"case": "1", "robot": "d", "activity": "w!", "lifecycle": "start", "msg_id": "m", "t": 11},
        {
            "case": "1",
            "robot": "d",
            "activity": "w!",
            "lifecycle": "complete",
            "msg_id": "m",
            "t": 12,
        },
        {
            "case": "1",
            "robot": "t",
            "activity": "w?",
            "lifecycle": "start",
            "msg_id": "m",
            "t": 11.5,
        },
        {
            "case": "1",
            "robot": "t",
            "activity": "w?",
            "lifecycle": "complete",
            "msg_id": "m",
            "t": 12,
        },
    )
    ranking = find_bottlenecks(log).table.set_index("kind")
    assert ranking.loc["rework", "total"] == 10 + 1  # the wait before the resend and the resend
    assert ranking.loc["queueing", "total"] == 11.5
    assert "waiting" not in ranking.index  # the receiver idling for the message is not counted


def test_drill_down_and_nothing_to_report(known_bottleneck, events):
    only_d = find_bottlenecks(known_bottleneck, activity="d").table
    assert set(only_d["activity"]) == {"d"}
    steady = events(
        {"case": "1", "robot": "r", "activity": "a", "lifecycle": "start", "t": 0},
        {"case": "1", "robot": "r", "activity": "a", "lifecycle": "complete", "t": 5},
    )
    result = find_bottlenecks(steady)
    assert not result.has_data and "nothing delays" in result.message


@pytest.fixture
def optional_wait(events):
    """30 missions of r1: plan, navigate (300-320 s, in every mission), deliver. In every third
    mission it also holds position for 150 s after navigating; r2 scans for 60 s throughout."""
    rows = []
    for case in range(30):
        t = 0.0
        steps = [("plan", 10 + case % 4), ("navigate", 300 + (case * 7) % 20)]
        steps += [("hold_position", 150)] if case % 3 == 0 else []
        steps += [("deliver", 20 + case % 2)]
        for activity, seconds in steps:
            t += 1
            rows += [
                (case, "r1", activity, "start", t),
                (case, "r1", activity, "complete", t + seconds),
            ]
            t += seconds
        rows += [(case, "r2", "scan", "start", 0), (case, "r2", "scan", "complete", 60)]
    return events(
        *[
            {"case": str(c), "robot": r, "activity": a, "lifecycle": lc, "t": t}
            for c, r, a, lc, t in rows
        ]
    )


def test_an_optional_waiting_activity_ranks_first_by_its_effect(optional_wait):
    from scipy.stats import mannwhitneyu

    ranking = find_bottlenecks(optional_wait).table
    first = ranking.iloc[0]
    assert (first["kind"], first["activity"], first["robot"]) == ("activity", "hold_position", "r1")
    # the cases with it against the cases without it, counted here with pandas and scipy
    times = optional_wait.groupby("case:concept:name")["time:timestamp"]
    seconds = (times.max() - times.min()).dt.total_seconds()
    has = optional_wait.groupby("case:concept:name")["concept:name"].agg(
        lambda names: "hold_position" in set(names)
    )
    with_it, without = seconds[has], seconds[~has]
    assert (first["cases"], first["cases_without"]) == (len(with_it), len(without)) == (10, 20)
    assert first["longer_by"] == pytest.approx(with_it.mean() - without.mean())
    assert first["extra_median"] == pytest.approx(with_it.median() - without.median())
    assert first["delay_per_case"] == pytest.approx((with_it.mean() - without.mean()) / 3)
    expected_p = mannwhitneyu(with_it, without, method="asymptotic").pvalue
    assert first["p_value"] == pytest.approx(expected_p)
    # the transitions and path that come with it are the same cases: named, not ranked again
    assert "transition navigate -> hold_position (r1)" in first["also"]
    assert "2m" in first["explanation"] and "10 of 30 cases" in first["explanation"]
    # navigate is long but in every case: it has no effect to measure, and its own duration
    # is never reported as waiting before it
    navigate = ranking[ranking["activity"] == "navigate"]
    assert set(navigate["kind"]) <= {"delay", "waiting"}
    assert navigate.loc[navigate["kind"] == "waiting", "mean"].max() == pytest.approx(1.0)
    assert ranking.loc[ranking["activity"] == "scan", "kind"].tolist() == []


def test_queueing_for_an_activity_another_robot_is_doing(events):
    # two robots, one charger: r2 waits 20 s for r1 to finish charging, 5 s of it before
    log = events(
        {"case": "1", "robot": "r1", "activity": "charge", "lifecycle": "start", "t": 0},
        {"case": "1", "robot": "r1", "activity": "charge", "lifecycle": "complete", "t": 30},
        {"case": "1", "robot": "r2", "activity": "drive", "lifecycle": "start", "t": 0},
        {"case": "1", "robot": "r2", "activity": "drive", "lifecycle": "complete", "t": 5},
        {"case": "1", "robot": "r2", "activity": "charge", "lifecycle": "start", "t": 30},
        {"case": "1", "robot": "r2", "activity": "charge", "lifecycle": "complete", "t": 40},
    )
    ranking = find_bottlenecks(log).table.set_index(["kind", "robot"])
    assert ranking.loc[("resource", "r2"), "total"] == 30 - 5  # r1 charged all the while
    assert ("waiting", "r2") not in ranking.index
    assert "queues" in ranking.loc[("resource", "r2"), "explanation"]


@pytest.fixture
def detour_and_quick_messages(events):
    """8 runs: r1 does a (0-10 s) and b (10 s); in runs 0-3 it makes a 20 s detour between
    them. Every run r1 tells r2 'done!' after b, received 10 ms later.

    By hand: runs 0-3 take 40.01 s, runs 4-7 20.01 s (the last receipt ends them); the detour
    adds 20 s to 4 of 8 runs (10 s per run, 80 of 240.08 s: 33 %), its runs all longer
    (Mann-Whitney, 4 against 4, U = 16, ties of 4 and 4: sigma = sqrt(16/12 * (9 - 120/56)) =
    3.024, z = (16 - 8 - 0.5) / 3.024 = 2.48, p = 0.013); the messages wait 10 ms per run
    (0.03 % of the runs' time)."""
    rows = []
    for run in range(8):
        t = 0.0
        steps = [("a", 10)] + ([("detour", 20)] if run < 4 else []) + [("b", 10)]
        for activity, seconds in steps:
            rows += [
                (run, "r1", activity, "start", t, None),
                (run, "r1", activity, "complete", t + seconds, None),
            ]
            t += seconds
        rows += [
            (run, "r1", "done!", "complete", t, "m"),
            (run, "r2", "done?", "complete", t + 0.01, "m"),
        ]
    return events(
        *[
            {"case": str(c), "robot": r, "activity": a, "lifecycle": lc, "t": t, "msg_id": m}
            for c, r, a, lc, t, m in rows
        ]
    )  # fmt: skip


def test_a_tiny_or_untested_effect_never_ranks_above_a_real_one(detour_and_quick_messages):
    ranking = find_bottlenecks(detour_and_quick_messages).table
    first = ranking.iloc[0]
    assert (first["kind"], first["activity"], bool(first["ranked"])) == ("activity", "detour", True)
    assert first["delay_per_case"] == pytest.approx(10.0)
    assert first["share"] == pytest.approx(80 / (4 * 40.01 + 4 * 20.01))
    assert "33% of the runs' time; p = 0.013, unlikely to be chance" in first["explanation"]
    queueing = ranking[ranking["kind"] == "queueing"].iloc[0]
    assert queueing["delay_per_case"] == pytest.approx(0.01)
    assert not queueing["ranked"] and "under 1% of a run" in queueing["explanation"]
    # every ranked row before every other
    flags = ranking["ranked"].tolist()
    assert flags == sorted(flags, reverse=True)


@pytest.fixture
def escort_and_aborted_runs(events):
    """6 runs. Runs 0-3 complete: search (0-60 s), then escort (60 s to 100, 110, 120, 130 s).
    Runs 4-5 abort: the search ends aborted at 20 s, nothing follows.

    By hand: every completed run has the escort, so among completed runs it explains nothing
    (no completed run without it); the 2 aborted runs are left out, not 'the others'."""
    rows = []
    for run in range(6):
        if run < 4:
            end = 100 + 10 * run
            rows += [(run, "search", "start", 0), (run, "search", "complete", 60)]
            rows += [(run, "escort", "start", 60), (run, "escort", "complete", end)]
        else:
            rows += [(run, "search", "start", 0), (run, "search", "aborted", 20)]
    return events(
        *[
            {"case": str(c), "robot": "ugv_1", "activity": a, "lifecycle": lc, "t": t}
            for c, a, lc, t in rows
        ]
    )


def test_the_outcome_is_held_fixed(escort_and_aborted_runs):
    result = find_bottlenecks(escort_and_aborted_runs)
    assert result.summary["aborted_runs_left_out"] == 2
    assert result.summary["compared"] == "completed runs against completed runs"
    assert result.summary["cases"] == 4
    table = result.table
    escort = table[(table["activity"] == "escort") & (table["kind"] == "activity")]
    assert escort.empty
    # every comparison is among the 4 completed runs
    assert (table["cases"] <= 4).all() and (table["cases_without"].fillna(0) <= 4).all()
    assert not table["ranked"].any()  # 4 runs with steady costs only: nothing shown for sure
    delays = find(escort_and_aborted_runs).answer("delays")
    assert delays.sentences[0] == (
        "Runs are compared with runs of the same outcome: the completed runs against each "
        "other, leaving out 2 runs that did not complete."
    )


def test_the_figure_is_plotly_express_bar_chart(known_bottleneck):
    """The bars are built from graph objects; the JSON is the same text as plotly express'
    bar chart of the same candidates (what the figure was drawn by before)."""
    import plotly.express as px

    from robotale.enhancement.bottlenecks import _figure, _shown

    result = find_bottlenecks(known_bottleneck)
    # a robot left out and a second kind, so that the legend and the "-" robot are compared
    ranking = result.table.copy()
    ranking.loc[ranking.index[-1], ["robot", "kind"]] = [None, "queueing"]
    shown = _shown(ranking)
    expected = px.bar(
        shown,
        x="delay_per_case",
        y="candidate",
        color="kind",
        orientation="h",
        hover_data=["explanation"],
        title="Bottlenecks: seconds they add per case",
    ).update_yaxes(autorange="reversed")
    assert len(expected.data) == 2  # one trace per kind
    assert _figure(ranking).to_json() == expected.to_json()
