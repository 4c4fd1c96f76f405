"""``discover bpmn`` hands pm4py's inductive miner its variants directly, through pm4py's
internal classes, to skip building a DataFrame, and makes two of the miner's steps (the
directly-follows graph of a sub-log, the concurrency cut's projection) in one pass. That route
must give the tree pm4py's own public function gives on the same traces as a log, with and
without a noise threshold, so a pm4py upgrade that changes its internals fails here rather than
in a discovered model."""

from __future__ import annotations

import random
from collections import Counter

import pandas as pd
import pm4py
import pytest
from pm4py.util.compression.util import discover_dfg_uvcl

from robotale.discovery.inductive import directly_follows, inductive_tree


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


def _interleaved(seed: int) -> list[list[str]]:
    """Forty traces of a robot doing three things at once, their steps interleaved at random
    (concurrency cuts nested in sequences and loops), and some with a step left out."""
    chance = random.Random(seed)
    traces = []
    for _ in range(40):
        threads = [
            ["go_to", *["scan"] * chance.randint(0, 2), "report"],
            ["listen?", "reply!"] if chance.random() < 0.8 else ["listen?"],
            [chance.choice(["charge", "wait"])],
        ]
        trace = ["start"]
        while any(threads):
            thread = chance.choice([t for t in threads if t])
            trace.append(thread.pop(0))
        traces.append([*trace, "end"])
    return traces


def _free(seed: int) -> list[list[str]]:
    """Sixty traces of random steps, every one distinct: the flower-like logs of robots that
    interleave freely, where the concurrency cut splits every activity apart."""
    chance = random.Random(seed)
    names = ["explore", "move", "scan", "charge", "msg!", "msg?"]
    return [[chance.choice(names) for _ in range(chance.randint(1, 12))] for _ in range(60)]


@pytest.mark.parametrize("seed", [1, 2, 3])
@pytest.mark.parametrize("noise", [0.0, 0.2])
@pytest.mark.parametrize("made", [_traces, _interleaved, _free])
def test_the_variant_route_gives_pm4pys_own_tree(made, seed, noise):
    traces = made(seed)
    ours = inductive_tree(traces, noise)
    theirs = pm4py.discover_process_tree_inductive(_as_log(traces), noise_threshold=noise)
    assert str(ours) == str(theirs)


def test_the_interleaved_traces_are_mined_with_a_concurrency_cut():
    """The faster projection is the one exercised above: the trees have a parallel block."""
    assert "+(" in str(inductive_tree(_interleaved(1), 0.0))
    assert "+(" in str(inductive_tree(_free(1), 0.0))


@pytest.mark.parametrize("made", [_traces, _interleaved, _free])
def test_the_directly_follows_graph_is_pm4pys(made):
    variants = Counter(tuple(trace) for trace in made(4))
    variants[()] += 2  # runs that did nothing count for no activity
    ours, theirs = directly_follows(variants), discover_dfg_uvcl(variants)
    for part in ("graph", "start_activities", "end_activities"):
        assert list(getattr(ours, part).items()) == list(getattr(theirs, part).items()), part
