"""One analysis shared by all perspectives gives what each perspective gives on its own, and
the vectorised medians equal numpy's on the values they stand for."""

import json
import math

import numpy as np
import pandas as pd
import pytest

import robotale.enhancement.context as context
from robotale.enhancement import (
    LogAnalysis,
    all_perspectives,
    battery_perspective,
    communication_perspective,
    find_bottlenecks,
    performance_perspective,
)
from robotale.enhancement.bottlenecks import _medians_with_zeros
from robotale.enhancement.effects import _medians_without
from robotale.enhancement.result import Figures
from robotale.eventlog.schema import CASE, TIMESTAMP

ALONE = {
    "communication": communication_perspective,
    "battery": battery_perspective,
    "performance": performance_perspective,
    "bottlenecks": find_bottlenecks,
}


@pytest.fixture(scope="module")
def daily_log(thesis_log) -> pd.DataFrame:
    """The thesis log with one case per day (five runs), so cases can be compared."""
    return thesis_log.assign(**{CASE: thesis_log[TIMESTAMP].dt.strftime("%Y-%m-%d")})


def _json(perspective) -> str:
    return json.dumps(perspective.to_dict(), sort_keys=True)


@pytest.mark.parametrize("focus", [{}, {"robot": "drone"}, {"activity": "takeoff"}])
def test_shared_analysis_matches_each_perspective_alone(daily_log, focus):
    together = all_perspectives(daily_log, **focus)
    for name, perspective in ALONE.items():
        assert _json(together[name]) == _json(perspective(daily_log, **focus)), name


def test_activity_instances_are_built_once_per_analysis(daily_log, monkeypatch):
    calls = []
    real = context.activity_instances

    def counted(log, carry=()):
        calls.append(tuple(carry))
        return real(log, carry)

    monkeypatch.setattr(context, "activity_instances", counted)
    analysis = LogAnalysis(daily_log)
    performance_perspective(analysis)
    find_bottlenecks(analysis)
    communication_perspective(analysis)
    assert calls == [()]


def test_medians_of_the_other_cases_equal_numpy():
    rng = np.random.default_rng(1)
    for _ in range(200):
        n = int(rng.integers(1, 25))
        values = np.round(rng.normal(size=n) * 3)  # rounded: many ties
        members = pd.DataFrame(
            {"k": rng.integers(0, 6, 40), "_i": rng.integers(0, n, 40)}
        ).drop_duplicates()
        grouped = members.groupby("k", sort=False)["_i"]
        got = _medians_without(grouped, values)
        for name, index in grouped:
            others = np.ones(n, dtype=bool)
            others[index.to_numpy()] = False
            want = float(np.median(values[others])) if others.any() else math.nan
            assert got[name] == want or (math.isnan(want) and math.isnan(got[name]))


def test_zero_padded_medians_equal_numpy():
    rng = np.random.default_rng(2)
    for _ in range(200):
        width = int(rng.integers(1, 12))
        ids = rng.integers(0, 5, 30)
        values = np.round(rng.normal(size=30) * 2, 1)
        got = _medians_with_zeros(ids, values, width)
        for name in np.unique(ids):
            mine = values[ids == name]
            padded = np.pad(mine, (0, max(width - len(mine), 0)))
            assert got[name] == float(np.median(padded))


def test_figures_are_drawn_once_and_only_when_read():
    drawn = []
    figures = Figures({"a": lambda: drawn.append("a") or "A", "b": lambda: "B"})
    assert list(figures) == ["a", "b"] and drawn == []
    assert figures["a"] == "A" and figures["a"] == "A" and drawn == ["a"]
    assert dict(figures) == {"a": "A", "b": "B"} and drawn == ["a"]


@pytest.mark.parametrize(
    "values",
    [
        np.array([], dtype=np.int64),
        np.array([7], dtype=np.int64),
        np.array([3, -1, 3, 2, np.iinfo(np.int64).min, 2], dtype=np.int64),
        np.random.default_rng(5).integers(0, 50, 1_000),
        np.random.default_rng(6).random(500),
    ],
)
def test_sorted_distinct_is_numpys_unique(values):
    found = context.sorted_distinct(values)
    expected = np.unique(values)
    assert found.dtype == expected.dtype
    np.testing.assert_array_equal(found, expected)
