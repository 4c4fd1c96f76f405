import re

import pytest

from robotale.discovery import LogFilter, discover_dfg, graph_to_svg
from robotale.discovery.graph import Edge, Node, ProcessGraph
from robotale.errors import RobotaleError


def svg_texts(svg: str) -> list[str]:
    return re.findall(r"<text[^>]*>(.*?)</text>", svg)


def test_drone_dfg_draws_every_node_and_count(thesis_log):
    graph = discover_dfg(thesis_log, LogFilter(robots=["drone"]))
    texts = svg_texts(graph_to_svg(graph))
    for node in graph.nodes:
        assert node.label in texts
    for edge in graph.edges:
        assert str(edge.count) in texts


def test_performance_labels_show_mean_time(thesis_log):
    graph = discover_dfg(thesis_log, LogFilter(robots=["drone"]))
    texts = svg_texts(graph_to_svg(graph, labels="performance"))
    # weed_found -> weed_position! waits 10 s every time (110 times)
    assert "10.0s (110)" in texts


def test_names_with_graphviz_syntax_stay_one_node():
    graph = ProcessGraph(
        kind="ekg",
        nodes=[Node("a:b", "a:b", count=1), Node('x"y\\z', 'x"y\\z', count=2)],
        edges=[Edge("a:b", 'x"y\\z', 3)],
    )
    texts = svg_texts(graph_to_svg(graph))
    assert "a:b" in texts and "x&quot;y\\z" in texts and "3" in texts


def test_without_dot_the_message_says_what_to_install(thesis_log, monkeypatch, tmp_path):
    monkeypatch.setenv("PATH", str(tmp_path))  # a PATH on which Graphviz does not exist
    graph = discover_dfg(thesis_log, LogFilter(robots=["drone"]))
    with pytest.raises(RobotaleError, match="Graphviz's `dot` program"):
        graph_to_svg(graph)
