"""A stored run as the Mission page replays it: the run's state at a moment and its window
(:mod:`robotale.enhancement.mission`), the site it took place in (:mod:`robotale.results.site`)
and, with the model that drove it, the BPMN elements each robot was in and the sequence flows
it took so far.

A log's activities are the labels the engines tag (:func:`element_label`), so an element is
found by its label among the events of the robot its pool binds, as on the Model page.
"""

from __future__ import annotations

import json
from collections import Counter, deque
from dataclasses import dataclass
from itertools import pairwise
from pathlib import Path
from typing import Any

import pandas as pd
from neo4j import Driver

from robotale.discovery.online import pool_replays
from robotale.enhancement.mission import SLOW_COLUMNS, MissionRun, mission_run, slow_limits
from robotale.errors import InputError, ModelError
from robotale.fame_runtime.kinds import Kind
from robotale.fame_runtime.labels import element_label
from robotale.fame_runtime.model import Flow, Scope
from robotale.fame_runtime.parser import parse
from robotale.fame_runtime.splitter import split
from robotale.results.logdata import LogData, current_build

#: gateways and unlabelled events a path between two tagged elements may pass through
MAX_HOPS = 8


def stored_mission(driver: Driver, logs: LogData, name: str, case: str) -> MissionRun:
    """The run ``case`` of the stored log ``name``, kept per build on disk and in memory."""
    if not case:
        raise InputError("Name the run to replay (?case=).")
    build = current_build(driver, name)

    def compute() -> tuple[dict[str, Any], dict[str, pd.DataFrame]]:
        # the whole log's slow limits are kept with the prepared results, not computed per run
        slow = stored_slow_limits(driver, logs, name)
        return mission_run(logs.frame(driver, name), case, slow).parts()

    def load() -> MissionRun:
        # kept with the build: a later visit (or a restarted dashboard) reads the run's
        # tables instead of reading the whole log and building them again
        return MissionRun.from_parts(*logs.tables(driver, name, ("mission", str(case)), compute))

    run: MissionRun = logs.missions.get((name, build.key, str(case)), load)
    return run


def stored_slow_limits(driver: Driver, logs: LogData, name: str) -> pd.DataFrame:
    """What counts as a slow activity in the whole log (:func:`slow_limits`), the same for
    each of its runs the Mission page replays: kept once per build, not computed per run."""
    data = logs.result(
        driver,
        name,
        ("slow-limits",),
        lambda: {"limits": slow_limits(logs.frame(driver, name)).to_dict(orient="records")},
    )
    return pd.DataFrame(json.loads(data)["limits"], columns=SLOW_COLUMNS)


def mission_site(site: dict[str, Any] | None, run: MissionRun) -> dict[str, Any]:
    """The map's extent and fixed places: the run's ``site`` when it was simulated (its
    ``source`` is ``world``), else the extent of its positions (``positions``), else none."""
    if site is not None:
        return {**site, "source": "world" if site.get("field") else "manifest"}
    if run.positions.empty:
        return {"source": None}
    x, y = run.positions["x"], run.positions["y"]
    return {
        "source": "positions",
        "extent": [float(x.min()), float(y.min()), float(x.max()), float(y.max())],
    }


@dataclass(frozen=True)
class ModelMap:
    """Which elements of a model each robot's activities are."""

    #: robot -> label -> element ids
    labels: dict[str, dict[str, list[str]]]
    #: robot -> the scopes (process, sub-processes) of its pool
    scopes: dict[str, list[Scope]]

    def active(self, run: MissionRun, t: float) -> dict[str, list[str]]:
        """``{robot: [element id, ...]}`` of the activities running at ``t``."""
        found: dict[str, list[str]] = {}
        for row in run.active_instances(t).itertuples(index=False):
            ids = self.labels.get(row.robot, {}).get(row.activity, [])
            found.setdefault(row.robot, [])
            found[row.robot] += [i for i in ids if i not in found[row.robot]]
        return found

    def deviated(self, deviations: list[dict[str, Any]], t: float) -> dict[str, list[str]]:
        """``{robot: [element id, ...]}`` of the elements each robot started, by ``t``,
        where its pool's model did not allow it (:func:`deviations`)."""
        found: dict[str, list[str]] = {}
        for deviation in deviations:
            if deviation["t"] > t:
                break  # in start order
            robot = deviation["robot"]
            mine = found.setdefault(robot, [])
            ids = self.labels.get(robot, {}).get(deviation["activity"], [])
            mine += [i for i in ids if i not in mine]
        return {robot: ids for robot, ids in found.items() if ids}

    def waiting(self, run: MissionRun, t: float) -> dict[str, list[str]]:
        """``{robot: [element id, ...]}`` of the catch events each robot waits at at ``t``:
        in a scope of its pool where nothing of it runs, those the flows lead to (through
        gateways and elements nothing tags, an event-based gateway's every branch) from the
        last element it ended there, or from the process' start before it did anything, when
        the next element it starts there is one of them or nothing does. A sub-process it has
        not started an element of yet is not read (where it waits there is not in the log)."""
        found: dict[str, list[str]] = {}
        for robot, scopes in self.scopes.items():
            rows = run.instances[run.instances["robot"] == robot]
            labels = self.labels.get(robot, {})
            tagged = {i for label in set(rows["activity"]) for i in labels.get(label, [])}
            for number, scope in enumerate(scopes):
                ids = [_first_in(labels.get(a, []), scope) for a in rows["activity"]]
                inside = rows.assign(_id=ids).dropna(subset=["_id"])
                waits = _waiting_in(scope, inside, t, tagged, process=number == 0)
                mine = found.setdefault(robot, [])
                mine += [w for w in waits if w not in mine]
        return {robot: ids for robot, ids in found.items() if ids}

    def flows_taken(self, run: MissionRun, t: float) -> dict[str, int]:
        """``{flow id: times}``: for each robot and each scope of its pool (the process, a
        sub-process), the flows on the shortest path (through gateways and events it does
        not tag) from each element of the scope it started to the next one it started there
        by ``t``. Elements that run side by side in one scope have no path between them and
        add nothing."""
        taken: Counter[str] = Counter()
        started = run.instances[run.instances["start"] <= t]
        for robot, rows in started.groupby("robot", sort=False):
            labels = self.labels.get(str(robot), {})
            ids = [labels[a][0] for a in rows["activity"] if a in labels]
            # a path passes through what the robot never tags (gateways, plain events)
            seen = set(run.instances.loc[run.instances["robot"] == robot, "activity"])
            tagged = {i for label, found in labels.items() if label in seen for i in found}
            for scope in self.scopes.get(str(robot), []):
                inside = [i for i in ids if i in scope.nodes]
                for source, target in pairwise(inside):
                    taken.update(_path(scope, source, target, tagged))
        return dict(taken)


def model_map(model: Path, robots: list[str]) -> ModelMap:
    """The elements of ``model`` the log's ``robots`` are bound to."""
    try:
        assignments = split(parse(model), robots)
    except ModelError as error:
        raise InputError(f"{error}; the run's robots are {', '.join(robots)}.") from None
    labels: dict[str, dict[str, list[str]]] = {}
    scopes: dict[str, list[Scope]] = {}
    for assignment in assignments:
        mine = labels.setdefault(assignment.robot, {})
        for node in assignment.process.walk():
            mine.setdefault(element_label(node), []).append(node.id)
        process = assignment.process
        scopes[assignment.robot] = [process] + [
            n.scope for n in process.walk() if n.scope is not None
        ]
    return ModelMap(labels, scopes)


def deviations(model: Path, run: MissionRun, robots: list[str]) -> list[dict[str, Any]]:
    """Each start the model did not allow where the robot was, in start order (``robot``,
    ``activity``, ``t`` seconds): every robot's activity starts replayed on its pool's Petri
    net as ``robotale monitor`` replays tags live (:mod:`robotale.discovery.online`)."""
    try:
        replays = pool_replays(model, robots)
    except ModelError as error:
        raise InputError(f"{error}; the run's robots are {', '.join(robots)}.") from None
    found = []
    for row in run.instances.itertuples(index=False):  # in start order
        replay = replays.get(str(row.robot))
        if replay is not None and not replay.allows_start(str(row.activity)):
            found.append({"robot": str(row.robot), "activity": str(row.activity), "t": row.start})
    return found


def _first_in(ids: list[str], scope: Scope) -> str | None:
    return next((i for i in ids if i in scope.nodes), None)


def _waiting_in(
    scope: Scope, inside: pd.DataFrame, t: float, tagged: set[str], *, process: bool
) -> list[str]:
    """The catch events of ``scope`` a robot whose elements there are ``inside`` (``_id``,
    ``start``, ``end``) waits at at ``t`` (see :meth:`ModelMap.waiting`)."""
    before = inside[inside["start"] <= t]
    if (before["end"].isna() | (before["end"] > t)).any():
        return []  # something of it runs in this scope
    if before.empty:
        if not process:
            return []
        sources = [i for i, node in scope.nodes.items() if node.kind == Kind.START_EVENT]
    else:
        sources = [str(before["_id"].iloc[-1])]
    reachable = {c for source in sources for c in _catches_after(scope, source, tagged)}
    later = inside.loc[inside["start"] > t, "_id"]
    if not later.empty and later.iloc[0] not in reachable:
        return []  # it went on through elements the log names: not waiting at a catch
    return sorted(reachable)


def _catches_after(scope: Scope, source: str, tagged: set[str]) -> list[str]:
    """The intermediate catch events the flows of ``scope`` reach from ``source`` through
    gateways and untagged elements (at most :data:`MAX_HOPS` flows)."""
    outgoing: dict[str, list[str]] = {}
    for flow in scope.flows.values():
        outgoing.setdefault(flow.source, []).append(flow.target)
    found: list[str] = []
    frontier, seen = [source], {source}
    for _ in range(MAX_HOPS):
        following = []
        for node in frontier:
            for target in outgoing.get(node, []):
                if target in seen:
                    continue
                seen.add(target)
                element = scope.nodes.get(target)
                if element is not None and element.kind == Kind.INTERMEDIATE_CATCH_EVENT:
                    found.append(target)
                elif target not in tagged:
                    following.append(target)
        frontier = following
    return found


def _path(scope: Scope, source: str, target: str, tagged: set[str]) -> list[str]:
    """The flow ids of the shortest path from ``source`` to ``target`` in ``scope`` that
    passes only through elements nothing tags; [] when there is none."""
    if source not in scope.nodes or target not in scope.nodes:
        return []
    outgoing: dict[str, list[Flow]] = {}
    for flow in scope.flows.values():
        outgoing.setdefault(flow.source, []).append(flow)
    queue: deque[tuple[str, list[str]]] = deque([(source, [])])
    seen = {source}
    while queue:
        node, flows = queue.popleft()
        if len(flows) >= MAX_HOPS:
            continue
        for flow in outgoing.get(node, []):
            if flow.target == target:
                return [*flows, flow.id]
            if flow.target not in seen and flow.target not in tagged:
                seen.add(flow.target)
                queue.append((flow.target, [*flows, flow.id]))
    return []
