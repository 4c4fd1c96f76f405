"""SVG drawings of process graphs with Graphviz (needs its ``dot`` program)."""

from __future__ import annotations

import shutil

import graphviz

from robotale.discovery.graph import Edge, Node, ProcessGraph, format_seconds
from robotale.errors import RobotaleError

#: colours given to robots (nodes) and entity types (edges), in order of first appearance.
PALETTE = ("#1f77b4", "#2ca02c", "#ff7f0e", "#9467bd", "#8c564b", "#e377c2", "#17becf")
LABELS = ("frequency", "performance")


def require_dot() -> None:
    """Raise a clear error when Graphviz's ``dot`` program is not installed."""
    if shutil.which("dot") is None:
        raise RobotaleError(
            "drawing SVG needs Graphviz's `dot` program, which is not on PATH; install Graphviz "
            "(Debian package graphviz) or leave out the SVG output."
        )


def graph_to_svg(graph: ProcessGraph, labels: str = "frequency") -> str:
    """The graph drawn left to right as SVG text.

    ``labels`` chooses what edges show: ``frequency`` (how often) or ``performance`` (mean
    time between the two activities, with the count in brackets).
    """
    if labels not in LABELS:
        raise RobotaleError(f"unknown edge labels {labels!r}; choose one of {', '.join(LABELS)}.")
    require_dot()
    dot = graphviz.Digraph(graph_attr={"rankdir": "LR"}, node_attr={"fontname": "Helvetica"})
    robot_colours = _colours(sorted({n.robot for n in graph.nodes if n.robot}))
    edge_colours = _colours(sorted({e.entity_type for e in graph.edges if e.entity_type}))
    # Graphviz reads "a:b" as node a, port b: plain generated ids keep every name one node.
    ids = {node.id: f"n{i}" for i, node in enumerate(graph.nodes)}
    for node in graph.nodes:
        dot.node(ids[node.id], **_node_style(node, robot_colours))
    for edge in graph.edges:
        colour = edge_colours.get(edge.entity_type or "", "#444444")
        dot.edge(
            ids[edge.source],
            ids[edge.target],
            label=_edge_label(edge, labels),
            color=colour,
            fontcolor=colour,
            fontname="Helvetica",
            penwidth=str(_pen_width(edge, graph.edges)),
        )
    return dot.pipe(format="svg", encoding="utf-8")


def _node_style(node: Node, robot_colours: dict[str, str]) -> dict[str, str]:
    label = graphviz.escape(node.label)  # a backslash in a name is text, not a Graphviz escape
    if node.kind in ("start", "end"):
        fill = "#8fd18f" if node.kind == "start" else "#f08080"
        return {"label": label, "shape": "circle", "style": "filled", "fillcolor": fill}
    if node.kind == "entity":
        return {"label": label, "shape": "note", "style": "filled", "fillcolor": "#eeeeee"}
    colour = robot_colours.get(node.robot or "", "#dddddd")
    samples = node.properties.get("samples")  # an EKG class's samples: apart, never added
    extra = f" (+{samples} samples)" if samples else ""
    return {
        "label": f"{label}\n{node.count}{extra}",
        "shape": "box",
        "style": "rounded,filled",
        "fillcolor": colour + "40",
        "color": colour,
    }


def _edge_label(edge: Edge, labels: str) -> str:
    prefix = f"{graphviz.escape(edge.entity_type)}: " if edge.entity_type else ""
    if labels == "performance" and edge.durations.get("mean") is not None:
        return f"{prefix}{format_seconds(edge.durations['mean'])} ({edge.count})"
    return f"{prefix}{edge.count}"


def _pen_width(edge: Edge, edges: list[Edge]) -> float:
    busiest = max((e.count for e in edges), default=1) or 1
    return round(1 + 3 * edge.count / busiest, 2)


def _colours(keys: list[str]) -> dict[str, str]:
    return {key: PALETTE[i % len(PALETTE)] for i, key in enumerate(keys)}
