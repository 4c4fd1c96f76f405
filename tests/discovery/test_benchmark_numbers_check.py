"""The "same output" checks of ``benchmarks/discovery.py`` (and ``report.py``, which prints the
same check) and of ``benchmarks/read_csv.py`` on a small input: once where both sides did the
same work, once where one side was given other work, which each check must tell apart."""

from __future__ import annotations

import pandas as pd
import pytest
from benchmark_scripts import benchmark

from robotale.eventlog import schema


@pytest.fixture(scope="module")
def discovery():
    return benchmark("discovery")


@pytest.fixture(scope="module")
def log(discovery) -> pd.DataFrame:
    return discovery.synthetic_log(2_000)


def verdicts(said: str) -> dict[str, bool]:
    """Each check's name and whether it found the two sides equal."""
    parts = [part.rsplit(" (", 1)[0] for part in said.split("; ")]
    return {part.rsplit(" ", 1)[0]: part.endswith(" equal") for part in parts}


def test_pm4py_on_the_same_log_finds_robotales_numbers(discovery, log):
    said = verdicts(discovery.same_numbers(log, discovery.pm4py_same_work(log, rework=True)))
    assert len(said) == 7 and all(said.values()), said


def test_pm4py_on_a_log_with_a_longer_activity_is_told_apart(discovery, log):
    # one completion 5 s later, still before the next event of its robot: one instance longer
    completes = log[log[schema.LIFECYCLE].eq("complete")]
    first = completes.index[0]
    later = log.copy()
    later.loc[first, schema.TIMESTAMP] += pd.Timedelta(seconds=5)
    said = verdicts(discovery.same_numbers(log, discovery.pm4py_same_work(later, rework=True)))
    assert not said["mean duration per activity"]
    assert said["activity instances"]


def test_pm4py_on_a_log_missing_a_robot_is_told_apart(discovery, log):
    robot = log[schema.ROBOT].iloc[0]
    case = log[schema.CASE].iloc[0]
    fewer = log[~(log[schema.ROBOT].eq(robot) & log[schema.CASE].eq(case))]
    said = verdicts(discovery.same_numbers(log, discovery.pm4py_same_work(fewer, rework=True)))
    assert not said["activity instances"] and not said["robot spans"]


def test_reading_the_csv_is_checked_against_pandas_and_a_changed_file_told_apart(
    discovery, log, tmp_path
):
    read_csv = benchmark("read_csv")
    path = tmp_path / "log.csv"
    log.to_csv(path, index=False)
    ours = read_csv.robotale_read(path)
    assert read_csv.same(ours, read_csv.pandas_read(path))
    # a row fewer, an activity renamed, a time a second later: each another file
    fewer = tmp_path / "fewer.csv"
    log.iloc[:-1].to_csv(fewer, index=False)
    assert not read_csv.same(ours, read_csv.pandas_read(fewer))
    renamed = tmp_path / "renamed.csv"
    log.assign(**{schema.ACTIVITY: log[schema.ACTIVITY].replace("move", "drive")}).to_csv(
        renamed, index=False
    )
    assert not read_csv.same(ours, read_csv.pandas_read(renamed))
    later = log.copy()
    later.loc[later.index[7], schema.TIMESTAMP] += pd.Timedelta(seconds=1)
    moved = tmp_path / "moved.csv"
    later.to_csv(moved, index=False)
    assert not read_csv.same(ours, read_csv.pandas_read(moved))


def test_the_bpmn_benchmark_checks_both_models_hold_the_same_activities(log):
    bpmn = benchmark("discover_bpmn")
    typed = bpmn.typed(log)
    ours, theirs = bpmn.robotale_run(typed), bpmn.pm4py_from_log(typed)
    # by hand: the activities of the log's start events
    started = set(log.loc[log[schema.LIFECYCLE].eq("start"), schema.ACTIVITY])
    assert ours == theirs == started
    assert bpmn.same_activities({"robotale": ours, "pm4py": theirs})
    # pm4py given the log without one activity: another model
    gone = sorted(started)[0]
    fewer = bpmn.pm4py_from_log(typed[typed[schema.ACTIVITY].ne(gone)])
    assert not bpmn.same_activities({"robotale": ours, "pm4py": fewer})


def test_the_compare_benchmark_checks_the_runs_mean_durations_against_the_findings():
    from robotale.enhancement.compare import compare_logs
    from robotale.enhancement.findings import find

    compare = benchmark("compare")
    template = benchmark("dashboard").thesis_runs(3_000)
    first, second = compare.batch(template, 3_000, 1, 1.0), compare.batch(template, 3_000, 2, 1.1)
    reported, means = compare.mean_durations(
        compare_logs(first, second), [find(first), find(second)]
    )
    assert reported == pytest.approx(means)
    # the findings of a slower batch: other work, told apart
    slower = compare.batch(template, 3_000, 2, 1.3)
    _, other = compare.mean_durations(compare_logs(first, second), [find(first), find(slower)])
    assert reported != pytest.approx(other)
