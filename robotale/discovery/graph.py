"""The shape every discovered process model is returned in, ready to draw.

A :class:`ProcessGraph` is plain data: nodes and edges with counts and durations, which
``to_dict`` turns into JSON-serialisable dictionaries (the dashboard draws them with
cytoscape.js). DFGs and aggregated EKG models share it, so one renderer serves both.

Node: ``id``, ``label``, ``robot`` (the one robot that performs it, or ``None``), ``robots``,
``count``, ``kind`` (``activity``, ``start``, ``end`` or ``entity``) and ``durations``
(seconds: ``mean``, ``median``). Edge: ``source``, ``target``, ``label``, ``entity_type``
(the entity whose directly-follows relation it aggregates, ``None`` for the flattened DFG,
``msg`` for message flow), ``count`` and ``durations``.
"""

from __future__ import annotations

import json
import math
from dataclasses import asdict, dataclass, field
from typing import Any

import pandas as pd

START_NODE = "__start__"
END_NODE = "__end__"


@dataclass(slots=True)
class Node:
    id: str
    label: str
    count: int = 0
    robot: str | None = None
    robots: list[str] = field(default_factory=list)
    kind: str = "activity"
    durations: dict[str, float | None] = field(default_factory=dict)
    properties: dict[str, Any] = field(default_factory=dict)


@dataclass(slots=True)
class Edge:
    source: str
    target: str
    count: int
    label: str = ""
    entity_type: str | None = None
    durations: dict[str, float | None] = field(default_factory=dict)


@dataclass(slots=True)
class ProcessGraph:
    """A discovered model: ``kind`` is ``dfg`` or ``ekg``; ``info`` says how it was made."""

    kind: str
    nodes: list[Node] = field(default_factory=list)
    edges: list[Edge] = field(default_factory=list)
    info: dict[str, Any] = field(default_factory=dict)

    def node(self, node_id: str) -> Node:
        """The node with that id (``KeyError`` if there is none)."""
        for node in self.nodes:
            if node.id == node_id:
                return node
        raise KeyError(node_id)

    def edge_counts(self, entity_type: str | None = "*") -> dict[tuple[str, str], int]:
        """``{(source, target): count}``, for one entity type or (``"*"``) all of them."""
        return {
            (e.source, e.target): e.count
            for e in self.edges
            if entity_type == "*" or e.entity_type == entity_type
        }

    def to_dict(self) -> dict[str, Any]:
        return json_ready(
            {
                "kind": self.kind,
                "info": self.info,
                "nodes": [asdict(n) for n in self.nodes],
                "edges": [asdict(e) for e in self.edges],
            }
        )

    def to_json(self, indent: int | None = 2) -> str:
        return json.dumps(self.to_dict(), indent=indent, ensure_ascii=False)

    @classmethod
    def from_dict(cls, data: dict[str, Any]) -> ProcessGraph:
        return cls(
            kind=data["kind"],
            info=dict(data.get("info", {})),
            nodes=[Node(**n) for n in data["nodes"]],
            edges=[Edge(**e) for e in data["edges"]],
        )


def duration_stats(seconds) -> dict[str, float | None]:
    """Mean and median of a sequence of durations in seconds (``None`` when empty)."""
    values = [float(s) for s in seconds if s is not None and not math.isnan(float(s))]
    if not values:
        return {"mean": None, "median": None}
    values.sort()
    middle = len(values) // 2
    median = values[middle] if len(values) % 2 else (values[middle - 1] + values[middle]) / 2
    return {"mean": sum(values) / len(values), "median": median}


def format_seconds(seconds: float | None) -> str:
    """A short human duration: ``850ms``, ``12.3s``, ``4m05s``, ``2h03m``."""
    if seconds is None:
        return "-"
    if seconds < 1:
        return f"{seconds * 1000:.0f}ms"
    if seconds < 60:
        return f"{seconds:.1f}s"
    minutes, secs = divmod(round(seconds), 60)
    if minutes < 60:
        return f"{minutes}m{secs:02d}s"
    hours, minutes = divmod(minutes, 60)
    return f"{hours}h{minutes:02d}m"


#: values JSON writes as they are
_PLAIN = frozenset({str, int, bool, type(None)})


def json_ready(value: Any) -> Any:
    """``value`` with NaN, NaT, NA and infinities as ``None``, timestamps as ISO text and
    numpy scalars as Python numbers, so ``json.dumps`` writes strict JSON."""
    # the exact plain types first: a result holds hundreds of thousands of them, and the
    # general checks below cost a dozen calls each
    kind = type(value)
    if kind in _PLAIN:
        return value
    if kind is float:
        return value if math.isfinite(value) else None
    if kind is dict:
        return {k if type(k) is str else str(k): json_ready(v) for k, v in value.items()}
    if kind is list:
        return [json_ready(v) for v in value]
    if isinstance(value, dict):
        return {str(k): json_ready(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [json_ready(v) for v in value]
    if pd.api.types.is_scalar(value) and pd.isna(value):
        return None
    if hasattr(value, "isoformat"):
        return value.isoformat()
    if hasattr(value, "item"):  # numpy scalars
        value = value.item()
    if isinstance(value, float) and not math.isfinite(value):
        return None
    return value
