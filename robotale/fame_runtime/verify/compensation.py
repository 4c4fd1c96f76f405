"""What the exploration leaves out of compensation, said once per verdict.

The step table runs a compensation throw event as a plain throw (it passes on at once) and
never runs a compensation handler, so the handlers' elements are never reached in the
explored states. Rather than report them as unreachable, the verdict names them and states
the abstraction; their own flaws are not looked for.
"""

from __future__ import annotations

from collections.abc import Iterable, Iterator
from dataclasses import dataclass

from robotale.fame_runtime.kinds import EventKind, Kind
from robotale.fame_runtime.plan import NodePlan, ScopePlan


@dataclass(frozen=True)
class Compensation:
    throws: tuple[str, ...]  # ids of the compensation throw events
    handlers: tuple[str, ...]  # ids of the handlers (activities, event sub-processes)
    hidden: frozenset[str]  # every element id the exploration cannot reach because of it

    def sentence(self) -> str:
        throws = ", ".join(self.throws) or "none"
        handlers = ", ".join(self.handlers) or "none"
        return (
            f"compensation is not explored: compensation throw events ({throws}) pass on at "
            f"once and compensation handlers ({handlers}) never run, so nothing inside them "
            "is checked or reported"
        )


def compensation(plans: Iterable[ScopePlan]) -> Compensation | None:
    """What of ``plans`` belongs to compensation; None when they use none."""
    throws: dict[str, None] = {}
    handlers: dict[str, None] = {}
    hidden: set[str] = set()
    for scope in _scopes(plans):
        for node in scope.nodes.values():
            if node.throw is not None and node.throw.kind == EventKind.COMPENSATE:
                throws[node.node.id] = None
            if (
                node.node.kind == Kind.BOUNDARY_EVENT
                and node.node.event_kind == EventKind.COMPENSATE
            ):
                hidden.add(node.node.id)
        named = list(scope.compensations.values())
        if scope.compensation_handler is not None:
            named.append(scope.compensation_handler)
        for handler in named:
            handlers[handler.node.id] = None
            hidden.update(_inside(handler))
    if not (throws or handlers or hidden):
        return None
    return Compensation(tuple(throws), tuple(handlers), frozenset(hidden))


def _scopes(plans: Iterable[ScopePlan]) -> Iterator[ScopePlan]:
    pending, seen = list(plans), set()
    while pending:
        scope = pending.pop()
        if id(scope) in seen:
            continue
        seen.add(id(scope))
        yield scope
        for node in [*scope.nodes.values(), *scope.event_subprocesses]:
            pending.extend(_children(node))


def _children(node: NodePlan) -> list[ScopePlan]:
    found = [node.child] if node.child is not None else []
    if node.loop is not None and node.loop.body.child is not None:
        found.append(node.loop.body.child)
    return found


def _inside(handler: NodePlan) -> set[str]:
    """The handler's id and the ids of everything it holds."""
    ids = {handler.node.id}
    for scope in _scopes(_children(handler)):
        ids.update(n.node.id for n in scope.nodes.values())
        ids.update(n.node.id for n in scope.event_subprocesses)
    return ids
