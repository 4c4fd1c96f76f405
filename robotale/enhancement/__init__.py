"""Enhancement: spatial, communication, battery and performance perspectives and bottlenecks.

Each function takes a canonical event log and returns a :class:`Perspective` (tables, plotly
figures, a summary, or a message saying why there is no data); each can be narrowed to one
activity and/or robot for a drill-down::

    spatial_perspective(log, activity="explore", robot="drone", field=Field(0, 10, 0, 10))
"""

from robotale.enhancement.battery import battery_perspective, low_battery_events
from robotale.enhancement.bottlenecks import find_bottlenecks
from robotale.enhancement.communication import communication_perspective, message_table
from robotale.enhancement.context import LogAnalysis
from robotale.enhancement.performance import performance_perspective
from robotale.enhancement.report import all_perspectives, report_html, write_report
from robotale.enhancement.result import Perspective
from robotale.enhancement.spatial import Field, spatial_perspective

__all__ = [
    "Field",
    "LogAnalysis",
    "Perspective",
    "all_perspectives",
    "battery_perspective",
    "communication_perspective",
    "find_bottlenecks",
    "low_battery_events",
    "message_table",
    "performance_perspective",
    "report_html",
    "spatial_perspective",
    "write_report",
]
