"""What the engine keeps of a running process: tokens, the scopes they run in, the frames of
multi-instance instances, running loops and the completed activities compensation may undo.

Plain records: the :class:`~robotale.fame_runtime.engine.Engine` moves them, the behaviours
(:mod:`robotale.fame_runtime.behaviours`) read and change them.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

from robotale.fame_runtime.plan import NodePlan, ScopePlan

#: undoes what a token waits for (a subscription, a timer, a skill's run)
Undo = Callable[[], object]


class Absent:
    """The value of a variable a frame shadows that had no value outside it."""

    __slots__ = ()


ABSENT = Absent()


class Frame:
    """The variables of one multi-instance instance that are its own (BPMN 2.0 section
    10.3.8: every instance has its own ``loopCounter``, input item and output item). The
    engine keeps one variables dict for a robot; before it runs a token of an instance it
    installs that instance's frame (its values in, the outer ones kept aside) and takes it
    out again afterwards, so instances running side by side never see each other's item."""

    __slots__ = ("outer", "parent", "values")

    def __init__(self, parent: Frame | None, values: dict[str, Any]) -> None:
        self.parent = parent
        self.values = values  # the instance's own values while it is not installed
        self.outer: dict[str, Any] = {}  # what the variables held before it was installed

    def chain(self) -> list[Frame]:
        """This frame and the frames around it, outermost first."""
        frames: list[Frame] = []
        frame: Frame | None = self
        while frame is not None:
            frames.append(frame)
            frame = frame.parent
        return frames[::-1]


def install(variables: dict[str, Any], current: Frame | None, wanted: Frame | None) -> None:
    """Swap the frames installed in ``variables`` from ``current`` (and the frames around
    it) to ``wanted``; None: only the process's own variables."""
    leaving = current.chain() if current is not None else []
    entering = wanted.chain() if wanted is not None else []
    common = 0
    while common < min(len(leaving), len(entering)) and leaving[common] is entering[common]:
        common += 1
    for frame in reversed(leaving[common:]):
        for name in frame.values:
            frame.values[name] = variables.get(name, ABSENT)
            outer = frame.outer.pop(name)
            if outer is ABSENT:
                variables.pop(name, None)
            else:
                variables[name] = outer
    for frame in entering[common:]:
        for name, value in frame.values.items():
            frame.outer[name] = variables.get(name, ABSENT)
            if value is ABSENT:
                variables.pop(name, None)
            else:
                variables[name] = value


class Token:
    __slots__ = (
        "alive",
        "boundaries",
        "child",
        "flow",
        "frame",
        "generation",
        "instance",
        "node",
        "scope",
        "waits",
    )

    def __init__(self, scope: RunScope, node: NodePlan) -> None:
        self.frame: Frame | None = scope.frame  # the instance variables it runs with
        self.scope = scope
        self.node = node
        self.flow = ""  # the sequence flow it arrived by (joins count them)
        self.waits: list[Undo] = []  # undo what it waits for
        self.boundaries: list[Undo] = []  # disarm its activity's boundary events
        self.child: RunScope | None = None
        self.alive = True
        self.generation = 0  # stale skill completions are ignored
        self.instance: LoopRun | None = None  # the loop this token runs one instance of


def outer(token: Token) -> Token:
    """The token whose activity's boundary events catch for ``token``: an instance of a loop
    or multi-instance activity is caught around the whole activity."""
    return token.instance.holder if token.instance is not None else token


class LoopRun:
    """One running loop or multi-instance activity: the token waiting at it (``holder``)
    and its instances."""

    __slots__ = ("active", "completed", "holder", "items", "next", "node", "outputs")

    def __init__(self, holder: Token, node: NodePlan, items: list[Any] | None) -> None:
        self.holder = holder
        self.node = node
        self.items = items  # one per instance; None: a standard loop (until its condition)
        self.next = 0  # the index of the next instance to start
        self.completed = 0
        self.active: dict[Token, int] = {}  # running instance -> its index
        self.outputs: dict[int, Any] = {}  # instance index -> its output item


class Done:
    """An activity that completed and may be compensated (BPMN 2.0 section 10.6.5): the
    scope it completed in, its instance frame, and for a sub-process its finished content."""

    __slots__ = ("child", "frame", "node", "scope")

    def __init__(
        self, node: NodePlan, scope: RunScope, frame: Frame | None, child: RunScope | None
    ) -> None:
        self.node, self.scope, self.frame = node, scope, frame
        self.child = child


class RunScope:
    """A running process, called process, sub-process or event sub-process."""

    __slots__ = (
        "armed",
        "depth",
        "done",
        "ended",
        "failed",
        "frame",
        "holder",
        "joins",
        "on_close",
        "parent",
        "plan",
        "safe",
        "tokens",
    )

    def __init__(self, plan: ScopePlan, parent: RunScope | None, holder: Token | None) -> None:
        self.plan = plan
        self.parent = parent
        self.holder = holder  # the token of the activity this scope runs inside
        self.frame = holder.frame if holder is not None else None
        self.depth: int = parent.depth + 1 if parent else 0
        self.tokens: set[Token] = set()
        self.joins: dict[str, list[Token]] = {}
        self.armed: dict[str, Undo] = {}  # event sub-process id -> disarm
        self.ended = False
        self.failed = False  # a top-level scope ended by an uncaught error or a model error
        self.safe = False  # its safe-state handler runs before it ends
        self.done: list[Done] = []  # its completed activities to compensate, oldest first
        self.on_close: Callable[[], object] | None = None  # a compensation's: what comes next


def nothing() -> None:
    return None
