"""A state of the collaboration and the working copy a step changes.

:data:`State` is what the explorer keeps: per robot, whether it has begun, its running
instances (the tokens of each scope, nested through sub-processes, called processes and loop
bodies) and the variables it tracks, all immutable and hashable. :class:`Robot`,
:class:`Scope` and :class:`Tok` are the working copy one step changes (:mod:`.space` thaws
and freezes them); :class:`Outcome` is what a step did.
"""

from __future__ import annotations

from collections.abc import Iterator
from dataclasses import dataclass, field
from typing import Any

from robotale.fame_runtime.plan import NodePlan, ScopePlan
from robotale.fame_runtime.tags import Tag
from robotale.fame_runtime.verify.registry import ElementKey


class NeedChoice(Exception):
    """A step met a choice beyond the ones it was given: ``options`` ways to go on."""

    def __init__(self, options: int) -> None:
        super().__init__(options)
        self.options = options


class Choices:
    """The answers a step is run with; asking beyond them raises :class:`NeedChoice`."""

    def __init__(self, answers: tuple[int, ...]) -> None:
        self.answers, self.used = answers, 0

    def pick(self, options: int) -> int:
        if options == 1:
            return 0
        if self.used < len(self.answers):
            self.used += 1
            return self.answers[self.used - 1]
        raise NeedChoice(options)


# -- the working state of one step ---------------------------------------------------------------


class Tok:
    __slots__ = ("alive", "child", "flow", "node", "scope", "since", "waiting")

    def __init__(self, scope: Scope, node: NodePlan, flow: str = "", waiting: str = "") -> None:
        self.scope, self.node, self.flow = scope, node, flow
        self.waiting = waiting  # "" running; "wait" at its node; "join" at a join
        self.child: Scope | None = None
        self.alive = True
        #: when its timers were armed, as a rank among the state's timers (their order)
        self.since = 0


class Scope:
    __slots__ = ("closed", "fired", "holder", "plan", "robot", "tokens")

    def __init__(self, robot: Robot, plan: ScopePlan | None, holder: Tok | None) -> None:
        self.robot, self.plan, self.holder = robot, plan, holder  # plan None: a loop body
        self.tokens: list[Tok] = []
        self.fired: set[int] = set()  # interrupting event sub-processes that fired
        self.closed = False


@dataclass
class Robot:
    name: str
    plan: ScopePlan
    begun: bool = False
    instances: list[Scope] = field(default_factory=list)
    variables: dict[str, tuple[Any, str]] = field(default_factory=dict)  # value, who set it
    later: set[str] = field(default_factory=set)  # written by callbacks


#: a robot as the state holds it
RobotKey = tuple[bool, tuple[Any, ...], tuple[Any, ...], tuple[Any, ...]]
State = tuple[RobotKey, ...]


@dataclass
class Decision:
    """A gateway's choice in a step: which flows it took, and the values it read."""

    robot: str
    node: NodePlan
    taken: tuple[str, ...]
    #: variable, value, the element that set it, whether it did so in this same step
    reads: tuple[tuple[str, Any, str, bool], ...]


@dataclass
class Outcome:
    """What one step did."""

    state: State
    tags: list[Tag]
    reached: set[ElementKey]
    armed: set[ElementKey]
    fired: set[ElementKey]
    decisions: list[Decision]
    lost: list[tuple[str, NodePlan, str]]  # robot, thrower, topic: thrown, nobody caught it
    capped: bool  # a catcher was left out by TOKEN_CAP or INSTANCE_CAP
    failures: list[tuple[str, str, NodePlan, str]]  # kind, robot, element, sentence
    urgent: bool = False  # it only ran the next round of a loop that does not wait


def scopes(robot: Robot) -> Iterator[Scope]:
    stack = list(robot.instances)
    while stack:
        scope = stack.pop()
        yield scope
        stack.extend(t.child for t in scope.tokens if t.child is not None)
