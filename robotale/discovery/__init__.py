"""Discovery: directly-follows graphs, aggregated EKG models and conformance.

One function per task, each returning plain data (:class:`ProcessGraph`, tables)::

    graph = discover_dfg(log, LogFilter(robots=["drone"]))
    svg = graph_to_svg(graph)
"""

from robotale.discovery.conformance import ConformanceReport, check_conformance
from robotale.discovery.dfg import discover_dfg
from robotale.discovery.ekg import discover_ekg
from robotale.discovery.filters import LogFilter, filter_log
from robotale.discovery.graph import Edge, Node, ProcessGraph
from robotale.discovery.instances import activity_instances
from robotale.discovery.render import graph_to_svg

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
