"""A mission: a collaboration split over its robots, one engine each, on one bus and clock.

The short way to run a model::

    mission = Mission("agri.bpmn", robots=["drone", "tractor_1", "tractor_2"],
                      skills=SKILLS, library="blocks/", tag_sink=tags.append)
    mission.run(until=600)
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping
from pathlib import Path
from typing import Any

from robotale.errors import ModelError
from robotale.fame_runtime.bus import Bus, InProcessBus
from robotale.fame_runtime.clock import Clock, SimClock
from robotale.fame_runtime.engine import Engine
from robotale.fame_runtime.library import Library
from robotale.fame_runtime.model import Definitions, Problem, Process
from robotale.fame_runtime.parser import parse
from robotale.fame_runtime.plan import ScopePlan, deploy, findings
from robotale.fame_runtime.skills import Skill
from robotale.fame_runtime.splitter import Assignment, split
from robotale.fame_runtime.tags import TagSink


class Mission:
    """Engines for every robot of a collaboration (see :func:`~.splitter.split` for how pools
    bind robots). ``variables`` maps a robot to its initial variables."""

    def __init__(
        self,
        model: Definitions | str | Path,
        *,
        robots: Iterable[str] | None = None,
        clock: Clock | None = None,
        bus: Bus | None = None,
        skills: Mapping[str, Skill] | None = None,
        library: Library | str | Path | None = None,
        tag_sink: TagSink | None = None,
        variables: Mapping[str, Mapping[str, Any]] | None = None,
    ) -> None:
        self.definitions = model if isinstance(model, Definitions) else parse(model)
        self.clock = clock or SimClock()
        self.bus = bus or InProcessBus(self.clock)
        if library is not None and not isinstance(library, Library):
            library = Library(library)
        self.assignments: list[Assignment] = split(self.definitions, robots)
        plans = _deploy_all(self.assignments, skills or {}, library)
        self.engines: dict[str, Engine] = {
            a.robot: Engine(
                plans[id(a.process)],
                robot=a.robot,
                robot_type=a.robot_type,
                bus=self.bus,
                clock=self.clock,
                skills=skills,
                tag_sink=tag_sink,
                library=library,
                variables=(variables or {}).get(a.robot),
            )
            for a in self.assignments
        }

    def start(self) -> None:
        """Start every engine (all subscribe before any instance begins)."""
        for engine in self.engines.values():
            engine.start()

    @property
    def done(self) -> bool:
        """No robot runs an instance or is about to, no message is in flight and no timer
        is armed (a timer start event will start an instance)."""
        return self.idle and all(e.next_timer is None for e in self.engines.values())

    @property
    def idle(self) -> bool:
        """No robot runs an instance or is about to, and no message is in flight."""
        idle = all(engine.idle for engine in self.engines.values())
        return idle and not getattr(self.bus, "pending", 0)

    def whereabouts(self) -> list[str]:
        """One line per robot with a running instance: where its tokens are."""
        return [
            f"{robot} is at {', '.join(engine.where()) or 'the start of an instance'}"
            for robot, engine in self.engines.items()
            if not engine.idle
        ]

    def run(self, until: float | None = None) -> float:
        """Start (if needed) and run the simulated clock until the mission is done or
        ``until`` (absolute time); returns the time reached. Needs a :class:`SimClock`."""
        if not all(engine.started for engine in self.engines.values()):
            self.start()
        clock = self.clock
        if not isinstance(clock, SimClock):
            raise TypeError("Mission.run needs a SimClock; drive other clocks yourself")
        return clock.run(until=until, stop_when=lambda: self.done)

    def replace(self, robot: str, process: Process) -> None:
        """Give ``robot`` a new process at run time; its safe-state handler runs first."""
        self.engines[robot].replace(process)

    @property
    def failures(self) -> list[str]:
        return [f for engine in self.engines.values() for f in engine.failures]


def _deploy_all(
    assignments: list[Assignment], skills: Mapping[str, Skill], library: Library | None
) -> dict[int, ScopePlan]:
    """Each pool's process deployed once (robots of one pool share its plan); what no pool
    can run is refused in one ModelError naming every element of every pool, with its line."""
    plans: dict[int, ScopePlan] = {}
    found: list[Problem] = []
    for assignment in assignments:
        process = assignment.process
        if id(process) in plans:
            continue
        problems = findings(process, skills=skills, library=library)
        if problems:
            found += problems
            continue
        plans[id(process)] = deploy(process, skills=skills, library=library)
    if found:
        lines = "\n".join(str(p) for p in found)
        raise ModelError(
            f"the engine cannot run {len(found)} elements of the mission:\n{lines}", problems=found
        )
    return plans
