"""The splitter (thesis 4.1.3): one process per robot.

A single-instance pool binds the robot whose namespace is the pool's name (``Drone`` ->
``drone``, case and spaces aside). A multi-instance pool ``Tractor`` binds every robot named
``Tractor_<n>`` or ``tractor_<n>`` (guideline G1.2), so one model serves any number of robots.
"""

from __future__ import annotations

import re
from collections.abc import Iterable
from dataclasses import dataclass

from robotale.errors import ModelError
from robotale.fame_runtime.model import Definitions, Participant, Process


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
    assignments = []
    bound: set[str] = set()
    for pool, process in pools:
        mine = [r for r in names if r not in bound and _binds(pool, r, pools)]
        _check_count(definitions, pool, mine, robots is not None)
        bound.update(mine)
        assignments += [Assignment(r, pool.name, process, pool) for r in _ordered(mine)]
    unknown = [r for r in names if r not in bound]
    if unknown:
        listed = ", ".join(p.name + ("_<n>" if p.multi_instance else "") for p, _ in pools)
        raise ModelError(
            f"{definitions.file}: robot {', '.join(unknown)} matches no pool (pools: {listed})"
        )
    return assignments


def _binds(pool: Participant, robot: str, pools: list[tuple[Participant, Process]]) -> bool:
    if robot.lower() == namespace(pool.name):
        return True
    exact = any(robot.lower() == namespace(p.name) for p, _ in pools)
    pattern = re.escape(namespace(pool.name)) + r"_\d+"
    return pool.multi_instance and not exact and re.fullmatch(pattern, robot.lower()) is not None


def _check_count(definitions: Definitions, pool: Participant, robots: list[str], given: bool):
    if not pool.multi_instance:
        if len(robots) > 1:
            raise ModelError(
                f"{definitions.file}:{pool.line}: pool {pool.name} is single-instance but "
                f"robots {', '.join(robots)} all match it"
            )
        return
    if pool.maximum is not None and len(robots) > pool.maximum:
        raise ModelError(
            f"{definitions.file}:{pool.line}: pool {pool.name} allows at most {pool.maximum} "
            f"robots, {len(robots)} given ({', '.join(robots)})"
        )
    if given and pool.minimum and len(robots) < pool.minimum:
        raise ModelError(
            f"{definitions.file}:{pool.line}: pool {pool.name} needs at least {pool.minimum} "
            f"robots, {len(robots)} given"
        )


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
