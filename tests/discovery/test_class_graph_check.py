"""``benchmarks/class_graph.py`` checks that its two sides computed the same class graph: the
check on a small input, once where both are the same and once where one computed other work."""

from __future__ import annotations

import copy

import pytest
from benchmark_scripts import benchmark

from robotale.discovery.ekg_table import table_class_graph


@pytest.fixture(scope="module")
def check():
    return benchmark("class_graph").differences


@pytest.fixture(scope="module")
def graph(thesis_log):
    return table_class_graph("thesis", thesis_log, ["activity", "robot"], ["robot", "msg_id"])


def test_the_same_graph_passes(check, graph):
    same = copy.deepcopy(graph.to_dict())
    # the last bits of a mean, as Neo4j's avg sums in another order
    edge = next(e for e in same["edges"] if e["durations"].get("mean"))
    edge["durations"]["mean"] *= 1 + 1e-13
    assert check(graph.to_dict(), same) == []


def test_other_work_is_told_apart(check, graph, thesis_log):
    counted = copy.deepcopy(graph.to_dict())
    counted["edges"][0]["count"] += 1
    assert len(check(graph.to_dict(), counted)) == 1
    by_activity = table_class_graph("thesis", thesis_log, ["activity"], ["robot", "msg_id"])
    assert check(graph.to_dict(), by_activity.to_dict())
    one_flow = table_class_graph("thesis", thesis_log, ["activity", "robot"], ["robot"])
    assert check(graph.to_dict(), one_flow.to_dict())
