"""Model analysis before anything runs: ``robotale fame verify``.

:func:`verify` deploys every robot's process as the engines would (one engine per robot, the
pools bound by :func:`~robotale.fame_runtime.splitter.split`), explores the collaboration's
states breadth first (:mod:`.search`) under the abstraction of :mod:`.space` and
:mod:`.values`, and returns what it found, each finding with a shortest trace leading there.
docs/fame_runtime.md (*Verifying a mission*) says what is explored and what is abstracted.
"""

from __future__ import annotations

from collections.abc import Collection, Iterable
from dataclasses import dataclass, field

from robotale.fame_runtime.kinds import Kind
from robotale.fame_runtime.library import Library, resolve_call
from robotale.fame_runtime.model import Definitions, Process
from robotale.fame_runtime.plan import deploy
from robotale.fame_runtime.splitter import split
from robotale.fame_runtime.verify.compensation import compensation
from robotale.fame_runtime.verify.search import KINDS, Finding, explore, findings
from robotale.fame_runtime.verify.space import Space

__all__ = ["KINDS", "Finding", "Verdict", "verify"]

MAX_STATES = 200_000
TIMEOUT = 60.0


@dataclass
class Verdict:
    """What :func:`verify` found, and how much it explored."""

    file: str
    robots: list[str]
    states: int
    steps: int
    seconds: float
    bound: str  # "" when every reachable state was explored
    findings: list[Finding] = field(default_factory=list)
    reached: list[str] = field(default_factory=list)  # ids of the elements some token reached
    #: what the exploration leaves out of this model, one sentence each
    abstractions: list[str] = field(default_factory=list)

    @property
    def complete(self) -> bool:
        return not self.bound

    def as_dict(self) -> dict[str, object]:
        return {
            "file": self.file,
            "robots": self.robots,
            "states": self.states,
            "steps": self.steps,
            "seconds": round(self.seconds, 3),
            "complete": self.complete,
            "bound": self.bound or None,
            "abstractions": self.abstractions,
            "findings": [f.as_dict() for f in self.findings],
        }


def verify(
    definitions: Definitions,
    *,
    robots: Iterable[str] | None = None,
    skills: Collection[str] = (),
    library: Library | None = None,
    outside: Collection[str] = (),
    max_states: int = MAX_STATES,
    timeout: float = TIMEOUT,
    opaque_calls: bool = False,
) -> Verdict:
    """Explore the mission of ``definitions``; ``outside`` names the signals and errors the
    world (a camera, a skill, a battery monitor) may raise at any time. With ``opaque_calls``
    a call activity that calls nothing known runs like a skill (it ends, some time later),
    as when a model is verified without its building blocks. A process the engine cannot run
    raises the deployer's ModelError."""
    if opaque_calls:
        skills = {*skills, *unresolved_calls(definitions, skills, library)}
    assignments = split(definitions, robots)
    plans = [(a.robot, deploy(a.process, skills=skills, library=library)) for a in assignments]
    topics = frozenset(t if t.startswith("/") else f"/{t}" for t in outside)
    space = Space(plans, topics)
    graph = explore(space, max_states=max_states, timeout=timeout)
    found = findings(graph)
    abstractions = []
    left_out = compensation(plan for _, plan in plans)
    if left_out is not None:
        abstractions.append(left_out.sentence())
        found = [f for f in found if not _inside(f, left_out.hidden)]
    return Verdict(
        definitions.file.name,
        [name for name, _ in plans],
        len(graph.states),
        graph.steps,
        graph.seconds,
        graph.bound,
        found,
        sorted({element for _, element in graph.reached}),
        abstractions,
    )


def _inside(finding: Finding, hidden: frozenset[str]) -> bool:
    """Whether ``finding`` is only about elements the exploration does not run."""
    return finding.kind in ("unreachable", "never_fires") and set(finding.elements) <= hidden


def unresolved_calls(
    definitions: Definitions, skills: Collection[str], library: Library | None
) -> set[str]:
    """The called elements that are no skill, no process of the file and no building block
    (of the file's processes and the processes they call)."""
    found: set[str] = set()
    pending: list[Process] = list(definitions.processes.values())
    seen: set[int] = set()
    while pending:
        process = pending.pop()
        if id(process) in seen:
            continue
        seen.add(id(process))
        for node in process.walk():
            name = node.called_element
            if node.kind != Kind.CALL_ACTIVITY or node.embedded_process or name in skills:
                if node.embedded_process is not None:
                    pending.append(node.embedded_process)
                continue
            called = resolve_call(name, process, library)
            if called is None:
                found.add(name)
            else:
                pending.append(called)
    return found
