"""Every perspective, once: its name, the function that computes it, the options it takes
beside its focus, its headline on the command line and its place on the Perspectives page.

The report (:func:`~robotale.enhancement.report.all_perspectives`), ``robotale
perspectives`` (its ``--only`` choices and its printed lines), the prepared results and the
dashboard's Perspectives page all read this table, so a new perspective is one entry here.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass
from typing import Any

from robotale.enhancement.battery import battery_perspective
from robotale.enhancement.bottlenecks import find_bottlenecks
from robotale.enhancement.communication import communication_perspective
from robotale.enhancement.performance import performance_perspective
from robotale.enhancement.result import Perspective
from robotale.enhancement.spatial import spatial_perspective


@dataclass(frozen=True)
class PerspectiveKind:
    """One perspective of a log."""

    name: str
    #: ``compute(log_or_analysis, activity=..., robot=..., **options)``
    compute: Callable[..., Perspective]
    #: the one line ``robotale perspectives`` prints of its summary
    headline: Callable[[Mapping[str, Any]], str]
    #: its place on the Perspectives page (the report keeps the order of the table)
    page_position: int
    #: the report's options it takes (``field``, ``threshold``, ``delay_threshold``); their
    #: defaults are the function's own
    options: tuple[str, ...] = ()

    def taken(self, options: Mapping[str, Any]) -> dict[str, Any]:
        """Those of ``options`` this perspective takes."""
        return {key: value for key, value in options.items() if key in self.options}


def _spatial(summary: Mapping[str, Any]) -> str:
    covered = summary.get("field", {}).get("covered_fraction")
    field = f", {covered:.0%} of the field covered" if covered is not None else ""
    return f"{summary['positions']} positions{field}"


def _communication(summary: Mapping[str, Any]) -> str:
    return (
        f"{summary['messages']} messages, {summary['received']} received, "
        f"{summary['lost']} lost, {summary.get('unobserved', 0)} not observed as received, "
        f"{summary['resends']} resends "
        f"({summary.get('resends_new_id', 0)} under a new id), "
        f"{summary.get('delayed', 0)} delayed, {summary.get('channels', 0)} channels"
    )


def _battery(summary: Mapping[str, Any]) -> str:
    per_run = summary.get("used_per_run")
    used = (
        summary.get("battery_levels")
        if not per_run
        else "used per run: " + ", ".join(f"{r} {u:.1f}%" for r, u in per_run.items())
    )
    return f"{summary['low_battery_events']} low-battery events; {used}"


def _performance(summary: Mapping[str, Any]) -> str:
    share = summary.get("waiting_share")
    waiting = "" if share is None else f", robots wait {share:.0%} of their time"
    return (
        f"{summary['cases']} cases, {summary.get('variants', 0)} variants{waiting}, "
        f"slowest transition {summary['slowest_transition']}"
    )


def _bottlenecks(summary: Mapping[str, Any]) -> str:
    return f"first: {summary['first']}"


#: every perspective, in the order of the report and of ``robotale perspectives``' lines
PERSPECTIVES: tuple[PerspectiveKind, ...] = (
    PerspectiveKind("spatial", spatial_perspective, _spatial, 1, ("field",)),
    PerspectiveKind(
        "communication", communication_perspective, _communication, 2, ("delay_threshold",)
    ),
    PerspectiveKind("battery", battery_perspective, _battery, 3, ("threshold",)),
    PerspectiveKind("performance", performance_perspective, _performance, 4),
    # the bottleneck ranking leads the page: where the time went, before each perspective
    PerspectiveKind("bottlenecks", find_bottlenecks, _bottlenecks, 0),
)


def names() -> tuple[str, ...]:
    """The perspectives' names, in the report's order."""
    return tuple(kind.name for kind in PERSPECTIVES)


def page_names() -> tuple[str, ...]:
    """The perspectives' names in the order of the Perspectives page."""
    return tuple(kind.name for kind in sorted(PERSPECTIVES, key=lambda k: k.page_position))


def perspective_kind(name: str) -> PerspectiveKind:
    """The perspective named ``name``; KeyError when there is none."""
    found = {kind.name: kind for kind in PERSPECTIVES}
    return found[name]
