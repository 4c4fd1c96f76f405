"""The splitter (thesis 4.1.3): one process per robot.

A single-instance pool binds the robot whose namespace is the pool's name (``Drone`` ->
``drone``, case and spaces aside). A multi-instance pool ``Tractor`` binds every robot named
``Tractor_<n>`` or ``tractor_<n>`` (guideline G1.2), so one model serves any number of robots.
"""

from __future__ import annotations

import re
from collections.abc import Iterable
from dataclasses import dataclass
from pathlib import Path

from lxml import etree

from robotale.errors import ModelError
from robotale.fame_runtime.kinds import Kind
from robotale.fame_runtime.library import find_process
from robotale.fame_runtime.model import Definitions, Participant, Problem, Process


@dataclass(frozen=True, slots=True)
class Assignment:
    """One robot and the process it runs."""

    robot: str  # its namespace: drone, tractor_1
    robot_type: str  # its pool: Drone, Tractor
    process: Process
    pool: Participant


def namespace(pool_name: str) -> str:
    """The robot namespace a pool name stands for (``Robot Explorer`` -> ``robot_explorer``)."""
    return "_".join(pool_name.split()).lower()


def split(definitions: Definitions, robots: Iterable[str] | None = None) -> list[Assignment]:
    """The process of every robot. Without ``robots`` each single-instance pool binds its own
    namespace and each multi-instance pool its minimum number of robots (at least one)."""
    pools = definitions.pools()
    names = _default_robots(pools) if robots is None else [r.strip() for r in robots if r.strip()]
    bound: dict[str, list[str]] = {}
    for pool, _ in pools:
        taken = {r for robots_of in bound.values() for r in robots_of}
        bound[pool.id] = [r for r in names if r not in taken and _binds(pool, r, pools)]
    unknown = [r for r in names if not any(r in robots_of for robots_of in bound.values())]
    if unknown:
        listed = ", ".join(p.name + ("_<n>" if p.multi_instance else "") for p, _ in pools)
        raise ModelError(
            f"{definitions.file}: robot {', '.join(unknown)} matches no pool (pools: {listed})"
        )
    assignments = []
    for pool, process in pools:
        _check_count(definitions, pool, bound[pool.id], robots is not None)
        assignments += [Assignment(r, pool.name, process, pool) for r in _ordered(bound[pool.id])]
    return assignments


def _binds(pool: Participant, robot: str, pools: list[tuple[Participant, Process]]) -> bool:
    if robot.lower() == namespace(pool.name):
        return True
    exact = any(robot.lower() == namespace(p.name) for p, _ in pools)
    pattern = re.escape(namespace(pool.name)) + r"_\d+"
    return pool.multi_instance and not exact and re.fullmatch(pattern, robot.lower()) is not None


def _check_count(
    definitions: Definitions, pool: Participant, robots: list[str], given: bool
) -> None:
    if not pool.multi_instance:
        if len(robots) > 1:
            raise _pool_error(
                definitions,
                pool,
                f"pool {pool.name} is single-instance but robots {', '.join(robots)} all match it",
            )
        return
    if pool.maximum is not None and len(robots) > pool.maximum:
        raise _pool_error(
            definitions,
            pool,
            f"pool {pool.name} allows at most {pool.maximum} robots, {len(robots)} given "
            f"({', '.join(robots)})",
        )
    if given and pool.minimum and len(robots) < pool.minimum:
        raise _pool_error(
            definitions,
            pool,
            f"pool {pool.name} needs at least {pool.minimum} "
            f"robot{'s' if pool.minimum > 1 else ''}, {len(robots)} given",
        )


def _pool_error(definitions: Definitions, pool: Participant, sentence: str) -> ModelError:
    """``sentence`` about ``pool``, placed at the pool in its file."""
    problem = definitions.placed(Problem(str(definitions.file), pool.line, pool.id, sentence))
    return ModelError(str(problem), problems=[problem])


def _default_robots(pools: list[tuple[Participant, Process]]) -> list[str]:
    names = []
    for pool, _ in pools:
        base = namespace(pool.name)
        count = max(pool.minimum or 1, 1) if pool.multi_instance else 0
        names += [f"{base}_{n}" for n in range(1, count + 1)] if count else [base]
    return names


def _ordered(robots: list[str]) -> list[str]:
    """tractor_2 before tractor_10."""
    return sorted(
        robots, key=lambda r: [int(t) if t.isdigit() else t for t in re.split(r"(\d+)", r)]
    )


def unbound_pools(definitions: Definitions, assignments: list[Assignment]) -> list[str]:
    """The pools no robot runs."""
    used = {a.pool.id for a in assignments}
    return [p.name for p, _ in definitions.pools() if p.id not in used]


def process_file(assignment: Assignment) -> bytes:
    """A .bpmn file with only ``assignment``'s pool and process (and the processes of the same
    file it calls, and the signal and error declarations): what FAME's splitter sends a robot.
    The diagram is left out, since it would show elements that are no longer there."""
    process = assignment.process
    source = process.file
    if source is None or not source.is_file():
        raise ModelError(f"process {process.describe()} has no file to split")
    root = etree.fromstring(
        source.read_bytes(), etree.XMLParser(resolve_entities=False, no_network=True)
    )
    keep = _same_file_calls(process)
    for child in list(root):
        kind = etree.QName(child).localname if isinstance(child.tag, str) else ""
        if (kind == "process" and child.get("id") not in keep) or kind == "BPMNDiagram":
            root.remove(child)
        elif kind == "collaboration":
            for part in list(child):
                if part.get("processRef") != process.id:
                    child.remove(part)  # other pools, message flows between them
    xml: bytes = etree.tostring(root, xml_declaration=True, encoding="UTF-8")
    return xml


def _same_file_calls(process: Process) -> set[str]:
    """The ids of ``process`` and of the processes of its file it calls, transitively."""
    definitions = process.definitions
    keep, stack = set(), [process]
    while stack:
        current = stack.pop()
        if current.id in keep:
            continue
        keep.add(current.id)
        for node in current.walk():
            called = find_process(definitions, node.called_element) if definitions else None
            if node.kind == Kind.CALL_ACTIVITY and called is not None:
                stack.append(called)
    return keep


def write_split(assignments: list[Assignment], folder: Path) -> list[Path]:
    """One ``<robot>.bpmn`` per assignment in ``folder``; every file is prepared before the
    first is written, and each is written whole (temporary file, then renamed)."""
    contents = [(folder / f"{a.robot}.bpmn", process_file(a)) for a in assignments]
    folder.mkdir(parents=True, exist_ok=True)
    for path, data in contents:
        temporary = path.with_suffix(".bpmn.tmp")
        temporary.write_bytes(data)
        temporary.replace(path)
    return [path for path, _ in contents]
