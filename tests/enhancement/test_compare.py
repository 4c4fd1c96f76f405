"""``robotale compare`` on simulated batches with a change injected through the simulator's
settings (the tractors at half speed; one tractor less) and on two batches of the same
settings; every expected figure is computed here with pandas from the prepared logs."""

from __future__ import annotations

import json
import math
import re
import warnings
from dataclasses import replace
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from robotale.cli import main
from robotale.enhancement.bottlenecks import ALPHA
from robotale.enhancement.compare import (
    benjamini_hochberg,
    compare_logs,
    either,
    mann_whitney,
    welch,
)
from robotale.enhancement.effects import compare_cases
from robotale.eventlog.schema import ACTIVITY, CASE, LIFECYCLE, ROBOT, ROBOT_TYPE, TIMESTAMP
from robotale.sim.batch import simulate_batch
from robotale.sim.plans import adjust, plans, resolve_world

RUNS = 12
#: every run cuts as many weeds, so the runs of a batch differ by chance, not by their work
WEEDS = (4, 4)


def _simulate(world, seed: int, folder: Path) -> pd.DataFrame:
    from robotale.eventlog.prepare import prepare

    simulate_batch(plans(world, "agri", runs=RUNS, seed=seed), folder, workers=0)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return prepare(folder)


@pytest.fixture(scope="module")
def batches(tmp_path_factory) -> dict[str, pd.DataFrame]:
    root = tmp_path_factory.mktemp("compare")
    world = adjust(resolve_world("agri")[0], weeds=WEEDS)
    slow = replace(
        world,
        robots=tuple(
            replace(r, max_speed=r.max_speed / 2) if r.name == "tractor" else r
            for r in world.robots
        ),
    )
    one = adjust(world, counts={"tractor": 1})
    settings = {"base": (world, 1), "same": (world, 500), "slow": (slow, 1000), "one": (one, 1500)}
    return {name: _simulate(w, seed, root / name) for name, (w, seed) in settings.items()}


def _durations(log: pd.DataFrame, activity: str, robot_type: str) -> pd.Series:
    """Per run, the mean duration of ``activity`` by robots of ``robot_type``: each start
    paired with the next completion of the same robot and activity."""
    rows = log[(log[ACTIVITY] == activity) & (log[ROBOT_TYPE] == robot_type)]
    rows = rows[rows[LIFECYCLE].isin(["start", "complete"])].sort_values(TIMESTAMP, kind="stable")
    keys = [CASE, ROBOT]
    starts = rows[rows[LIFECYCLE] == "start"].copy()
    ends = rows[rows[LIFECYCLE] == "complete"].copy()
    starts["n"] = starts.groupby(keys).cumcount()
    ends["n"] = ends.groupby(keys).cumcount()
    paired = starts.merge(ends, on=[*keys, "n"], suffixes=("_s", "_e"))
    seconds = (paired[f"{TIMESTAMP}_e"] - paired[f"{TIMESTAMP}_s"]).dt.total_seconds()
    return seconds.groupby(paired[CASE]).mean()


def _run_seconds(log: pd.DataFrame) -> pd.Series:
    times = log.groupby(CASE)[TIMESTAMP]
    return (times.max() - times.min()).dt.total_seconds()


def _percent(a: pd.Series, b: pd.Series) -> float:
    return 100 * (b.mean() - a.mean()) / a.mean()


@pytest.mark.slow
def test_slower_tractors_are_the_first_sentence_with_their_size(batches):
    base, slow = batches["base"], batches["slow"]
    comparison = compare_logs(base, slow)
    first = comparison.sentences[0]
    move = _percent(_durations(base, "move", "Tractor"), _durations(slow, "move", "Tractor"))
    assert move > 50  # the injected change itself: half the speed, about twice the time
    found = re.search(r"tractor's move takes (\d+)% longer", first, re.IGNORECASE)
    assert found, first
    assert abs(int(found.group(1)) - move) <= 1.5, (first, move)
    if first.startswith("Runs are"):  # the runs' duration leads when it changed surely
        runs = _percent(_run_seconds(base), _run_seconds(slow))
        said = re.match(r"Runs are (\d+)% longer", first)
        assert said and abs(int(said.group(1)) - runs) <= 1.5, (first, runs)


@pytest.mark.slow
def test_one_tractor_less_is_the_first_sentence(batches):
    base, one = batches["base"], batches["one"]
    comparison = compare_logs(base, one)
    gone = sorted(set(base[ROBOT].dropna()) - set(one[ROBOT].dropna()))
    assert gone == ["tractor_2"]
    assert comparison.sentences[0] == (
        f"B runs without tractor_2: {one[ROBOT].nunique()} robots against {base[ROBOT].nunique()}."
    )


@pytest.mark.slow
def test_same_settings_call_no_more_than_chance(batches):
    """Different seeds, same settings: nothing changed, so the changes called significant
    may not exceed what chance gives at the level ``ALPHA`` (the procedure keeps the chance
    of any at all at ``ALPHA``)."""
    comparison = compare_logs(batches["base"], batches["same"])
    tested = comparison.facts["tested"]
    assert tested >= 20  # durations, frequencies, waits, messages, battery were all tested
    significant = comparison.changes[comparison.changes["q_value"] < ALPHA]
    assert len(significant) <= math.ceil(ALPHA * tested), significant
    assert not comparison.changes["ranked"].any()
    assert comparison.sentences[0].startswith("Runs are not significantly")


@pytest.mark.slow
def test_the_run_durations_compared_are_the_runs(batches):
    base, slow = batches["base"], batches["slow"]
    row = compare_logs(base, slow).changes.query("measure == 'run duration'").iloc[0]
    # the runs' durations from their first start to their last completion: within a second
    # of the first and last event of each run
    assert row["a"] == pytest.approx(_run_seconds(base).mean(), abs=1.0)
    assert row["b"] == pytest.approx(_run_seconds(slow).mean(), abs=1.0)
    assert (row["runs_a"], row["runs_b"]) == (RUNS, RUNS)


def test_benjamini_hochberg_by_hand():
    p = pd.Series([0.01, 0.04, 0.03, 0.5, None])
    # sorted 0.01, 0.03, 0.04, 0.5 (m = 4): 0.04, 0.06, 0.0533, 0.5; the running minimum
    # from the largest down gives 0.04, 0.0533, 0.0533, 0.5
    expected = [0.04, 0.04 * 4 / 3, 0.04 * 4 / 3, 0.5]
    assert benjamini_hochberg(p).iloc[:4].tolist() == pytest.approx(expected)
    assert pd.isna(benjamini_hochberg(p).iloc[4])


def test_mann_whitney_of_all_keys_at_once_is_the_effects_test_of_each():
    """The grouped test against :func:`compare_cases` (the bottlenecks' test) key by key, on
    values with ties, with a key only one side has and a key whose values are all equal."""
    rng = np.random.default_rng(3)
    rows = []
    for key, shift, size in (("k1", 0.0, 9), ("k2", 2.0, 14), ("k3", 0.5, 5)):
        for side in (0, 1):
            values = np.round(rng.normal(shift * side, 1.0, size + side * 3), 0)  # ties
            rows += [(key, side, f"r{side}_{i}", v) for i, v in enumerate(values)]
    rows += [("only_a", 0, "r0_0", 1.0), ("flat", 0, "r0_0", 2.0), ("flat", 1, "r1_0", 2.0)]
    long = pd.DataFrame(rows, columns=["subject", "side", "run", "value"])
    long = long.assign(measure="m", who="")
    table = mann_whitney(long).reset_index().set_index("subject")
    for key in ("k1", "k2", "k3"):
        mine = long[long["subject"] == key]
        values = pd.Series(mine["value"].to_numpy(), index=mine["side"].astype(str) + mine["run"])
        members = pd.DataFrame({"b": "b", CASE: values.index[mine["side"].to_numpy() == 1]})
        expected = compare_cases(members, "b", values).iloc[0]
        assert table.loc[key, "p_value"] == pytest.approx(expected["p_value"])
        assert table.loc[key, "difference"] == pytest.approx(expected["extra_mean"])
    assert pd.isna(table.loc["only_a", "p_value"]) and pd.isna(table.loc["flat", "p_value"])


@pytest.mark.slow
def test_cli_prints_sentences_and_writes_json(batches, tmp_path, capsys):
    paths = []
    for name in ("base", "slow"):
        path = tmp_path / f"{name}.csv"
        batches[name].to_csv(path, index=False)
        paths.append(str(path))
    out = tmp_path / "compare.json"
    assert main(["compare", *paths, "--json", str(out), "--top", "5"]) == 0
    printed = capsys.readouterr().out
    written = json.loads(out.read_text(encoding="utf-8"))
    assert written["sentences"][0] in printed
    assert re.search(r"tractor's move takes \d+% longer", written["sentences"][0], re.I)
    assert len(written["changes"]) == written["facts"]["tested"] + sum(
        1 for c in written["changes"] if c["q_value"] is None
    )


def test_cli_refuses_a_missing_file(tmp_path, capsys):
    missing = tmp_path / "nowhere.csv"
    assert main(["compare", str(missing), str(missing)]) == 1
    assert capsys.readouterr().err.strip() == f"robotale: {missing}: there is no such file."


def _outlier_batches(runs: int, waited: int) -> pd.DataFrame:
    """``runs`` runs a side of one measure; in B, ``waited`` of them waited 300 s more."""
    rng = np.random.default_rng(11)
    a = rng.normal(100.0, 5.0, runs)
    b = rng.normal(100.0, 5.0, runs)
    b[:waited] += 300.0
    rows = [(0, f"a{i}", v) for i, v in enumerate(a)] + [(1, f"b{i}", v) for i, v in enumerate(b)]
    long = pd.DataFrame(rows, columns=["side", "run", "value"])
    return long.assign(measure="run duration", subject="", who="")


def test_welch_of_all_keys_at_once_is_scipys_test_of_each():
    """The grouped test against scipy's Welch t-test on the per-run values pandas selects,
    key by key, with a key only one side has and a key without spread."""
    from scipy.stats import ttest_ind

    rng = np.random.default_rng(5)
    rows = []
    for key, shift, size in (("k1", 0.0, 9), ("k2", 2.0, 14), ("k3", 0.5, 5)):
        for side in (0, 1):
            values = rng.normal(shift * side, 1.0 + side, size + side * 3)
            rows += [(key, side, f"r{side}_{i}", v) for i, v in enumerate(values)]
    rows += [("only_a", 0, "r0_0", 1.0), ("only_a", 0, "r0_1", 2.0)]
    rows += [("flat", 0, f"r0_{i}", 2.0) for i in range(3)]
    rows += [("flat", 1, f"r1_{i}", 2.0) for i in range(3)]
    long = pd.DataFrame(rows, columns=["subject", "side", "run", "value"])
    long = long.assign(measure="m", who="")
    p = welch(long).droplevel(["measure", "who"])
    for key in ("k1", "k2", "k3"):
        mine = long[long["subject"] == key]
        a, b = (mine.loc[mine["side"] == side, "value"].to_numpy() for side in (0, 1))
        assert p[key] == pytest.approx(ttest_ind(b, a, equal_var=False).pvalue)
    assert pd.isna(p["only_a"]) and pd.isna(p["flat"])


@pytest.mark.parametrize(("runs", "waited", "called"), [(24, 6, True), (12, 4, False)])
def test_a_mean_moved_by_a_few_runs(runs, waited, called):
    """A few runs waiting 300 s: the ranks alone call it not significant; the combined test
    (the smaller p-value, doubled) is scipy's tests on the runs and calls 6 runs of 24. With
    4 of 12 it cannot: the permutation test of the mean difference gives about 0.08 (about
    the chance that a random split puts all four long runs on one side), and Welch's 0.04
    doubled is 0.08."""
    from scipy.stats import mannwhitneyu, ttest_ind

    long = _outlier_batches(runs, waited)
    a, b = (long.loc[long["side"] == side, "value"] for side in (0, 1))
    rank_p = mann_whitney(long)["p_value"]
    assert rank_p.iloc[0] == pytest.approx(mannwhitneyu(b, a).pvalue)
    assert rank_p.iloc[0] >= ALPHA
    combined = either(rank_p, welch(long).reindex(rank_p.index))
    expected = 2 * min(rank_p.iloc[0], ttest_ind(b, a, equal_var=False).pvalue)
    assert combined.iloc[0] == pytest.approx(expected)
    assert bool(combined.iloc[0] < ALPHA) == called
