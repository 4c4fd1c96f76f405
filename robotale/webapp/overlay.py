"""What the Model page paints on a BPMN collaboration: per element, how often the log shows it
and how often the robots deviated there.

A log's activities are the labels the engines tag (:func:`element_label`), so an element is
found in the log by its label among the events of the robots its pool binds (the splitter's
binding: ``Drone`` -> ``drone``, a multi-instance ``Tractor`` -> ``tractor_1`` ...). Deviations
come from :func:`robotale.discovery.conformance.check_conformance`: an ``unexpected`` activity
is painted on the elements of that label, a ``missing`` one likewise.
"""

from __future__ import annotations

from collections import Counter, defaultdict
from pathlib import Path
from typing import Any

import pandas as pd

from robotale.discovery.conformance import check_conformance
from robotale.discovery.instances import activity_instances
from robotale.errors import InputError, ModelError
from robotale.eventlog.schema import ACTIVITY, ROBOT
from robotale.fame_runtime.labels import element_label
from robotale.fame_runtime.model import Node
from robotale.fame_runtime.parser import parse
from robotale.fame_runtime.splitter import split


def frequencies(log: pd.DataFrame, model: Path) -> dict[str, dict[str, Any]]:
    """``{element id: {"count": n, "robots": [...]}}``: how often each element's activity
    happened, among the robots its pool binds."""
    instances = activity_instances(log)
    counts = Counter(
        zip(instances[ROBOT].astype(str), instances[ACTIVITY].astype(str), strict=True)
    )
    elements: dict[str, dict[str, Any]] = defaultdict(lambda: {"count": 0, "robots": []})
    for robot, node in _bound_nodes(log, model):
        seen = counts.get((robot, element_label(node)), 0)
        elements[node.id]["count"] += seen
        if seen:
            elements[node.id]["robots"].append(robot)
    return dict(elements)


def deviations(log: pd.DataFrame, model: Path) -> dict[str, Any]:
    """``{"elements": {element id: {"unexpected": n, "missing": m}}, "robots": [...]}``: the
    conformance deviations on the elements of their activity, and the fitness per robot."""
    report = check_conformance(log, model)
    found = Counter()
    for row in report.deviations.itertuples(index=False):
        found[(row.robot, row.activity, row.kind)] += int(row.count)
    elements: dict[str, dict[str, int]] = defaultdict(lambda: {"unexpected": 0, "missing": 0})
    for robot, node in _bound_nodes(log, model):
        for kind in ("unexpected", "missing"):
            if count := found.get((robot, element_label(node), kind), 0):
                elements[node.id][kind] += count
    return {"elements": dict(elements), "robots": report.to_dict()["robots"]}


def _bound_nodes(log: pd.DataFrame, model: Path) -> list[tuple[str, Node]]:
    """Every (robot, element) pair of the log's robots and their pools' processes."""
    if ROBOT not in log.columns:
        raise InputError("The log names no robots, so it cannot be compared with a model.")
    robots = sorted(log[ROBOT].dropna().astype(str).unique())
    try:
        assignments = split(parse(model), robots)
    except ModelError as error:
        raise InputError(f"{error}; the log's robots are {', '.join(robots)}.") from None
    return [(a.robot, node) for a in assignments for node in a.process.walk()]
