"""Discovery: directly-follows graphs, aggregated EKG models and conformance.

One function per task, each returning plain data (:class:`ProcessGraph`, tables)::

    graph = discover_dfg(log, LogFilter(robots=["drone"]))
    svg = graph_to_svg(graph)

The names below are loaded on first use: importing one module of the package (the BPMN
writer, the output helpers) then costs that module alone, not the graph database's driver
(``discover_ekg``) or the conformance checker, each a second or so to import.
"""

from __future__ import annotations

import importlib
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from robotale.discovery.conformance import ConformanceReport, check_conformance
    from robotale.discovery.dfg import discover_dfg
    from robotale.discovery.ekg import discover_ekg
    from robotale.discovery.filters import LogFilter, filter_log
    from robotale.discovery.graph import Edge, Node, ProcessGraph
    from robotale.discovery.instances import activity_instances
    from robotale.discovery.render import graph_to_svg

#: each public name -> the module that defines it
_HOMES = {
    "ConformanceReport": "conformance",
    "check_conformance": "conformance",
    "discover_dfg": "dfg",
    "discover_ekg": "ekg",
    "LogFilter": "filters",
    "filter_log": "filters",
    "Edge": "graph",
    "Node": "graph",
    "ProcessGraph": "graph",
    "activity_instances": "instances",
    "graph_to_svg": "render",
}

__all__ = [
    "ConformanceReport",
    "Edge",
    "LogFilter",
    "Node",
    "ProcessGraph",
    "activity_instances",
    "check_conformance",
    "discover_dfg",
    "discover_ekg",
    "filter_log",
    "graph_to_svg",
]


def __getattr__(name: str) -> Any:
    """A public name, its module imported the first time it is asked for."""
    home = _HOMES.get(name)
    if home is None:
        raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
    value = getattr(importlib.import_module(f"{__name__}.{home}"), name)
    globals()[name] = value  # asked once: later lookups find it without this function
    return value
