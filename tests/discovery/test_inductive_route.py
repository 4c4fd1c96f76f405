"""``discover bpmn`` hands pm4py's inductive miner its variants directly, through pm4py's
internal classes, to skip building a DataFrame. That route must give the tree pm4py's own
public function gives on the same traces as a log, with and without a noise threshold, so a
pm4py upgrade that changes its internals fails here rather than in a discovered model."""

from __future__ import annotations

import random

import pandas as pd
import pm4py
import pytest

from robotale.discovery.collaboration import _inductive_tree


def _as_log(traces: list[list[str]]) -> pd.DataFrame:
    """The traces as the DataFrame pm4py's public miner reads: case ids 0..n-1, one second
    between events."""
    rows = [
        {
            "case:concept:name": str(case),
            "concept:name": label,
            "time:timestamp": pd.Timestamp("2026-01-01", tz="UTC") + pd.Timedelta(seconds=step),
        }
        for case, trace in enumerate(traces)
        for step, label in enumerate(trace)
    ]
    return pd.DataFrame(rows)


def _traces(seed: int) -> list[list[str]]:
    """Fourteen traces (more than ten, so their ids sort differently as text and as numbers)
    over a small alphabet: choices, loops and optional steps."""
    chance = random.Random(seed)
    traces = []
    for _ in range(14):
        trace = ["take_off"]
        for _ in range(chance.randint(1, 3)):
            trace.append(chance.choice(["explore", "explore", "detect"]))
            if chance.random() < 0.3:
                trace.append("weed_found")
        trace.append(chance.choice(["land", "return_to_base"]))
        traces.append(trace)
    return traces


@pytest.mark.parametrize("seed", [1, 2, 3])
@pytest.mark.parametrize("noise", [0.0, 0.2])
def test_the_variant_route_gives_pm4pys_own_tree(seed, noise):
    traces = _traces(seed)
    ours = _inductive_tree(traces, noise)
    theirs = pm4py.discover_process_tree_inductive(_as_log(traces), noise_threshold=noise)
    assert str(ours) == str(theirs)
