"""Compensation (BPMN 2.0 sections 10.6.5 and 13.5.5): completed activities with something to
undo are remembered in their scope; a compensation throw runs their handlers, the last
completed first."""

from __future__ import annotations

from collections.abc import Callable
from typing import TYPE_CHECKING

from robotale.fame_runtime.behaviours.catching import caught
from robotale.fame_runtime.kinds import Run
from robotale.fame_runtime.plan import NodePlan
from robotale.fame_runtime.tokens import Done, Frame, RunScope, Token, nothing

if TYPE_CHECKING:
    from robotale.fame_runtime.engine import Engine


def compensable(token: Token, node: NodePlan, child: RunScope | None = None) -> None:
    """Remember a completed activity that has something to compensate: a compensation
    handler, or (a sub-process) a compensation event sub-process or completed content."""
    scope = token.scope
    if child is not None and not child.done and child.plan.compensation_handler is None:
        child = None
    if child is None and node.id not in scope.plan.compensations:
        return
    scope.done.append(Done(node, scope, token.frame, child))


def throw_compensation(
    engine: Engine, token: Token, node: NodePlan, then: Callable[[], object]
) -> bool:
    """Compensate the activity the event names, or every completed one of its scope (of
    the scope around, thrown in an event sub-process), the last completed first. True
    when the thrower goes on now; else ``then`` runs once the compensation is done."""
    throw = node.throw
    assert throw is not None  # the deployer gives every throwing node what it throws
    engine.tag.pair(throw.label)
    scope = token.scope
    if scope.holder is not None and scope.holder.node.behaviour == Run.EVENT_SUBPROCESS:
        assert scope.parent is not None  # an event sub-process runs inside a scope
        scope = scope.parent
    records = _take_done(scope, throw.topic)
    if not throw.wait or not records:
        _compensate_all(engine, records, nothing)
        return True
    generation = token.generation

    def resume() -> None:
        if token.alive and token.generation == generation:
            engine.enter_token(token)
            then()

    _compensate_all(engine, records, resume)
    return False


def _compensate_all(engine: Engine, records: list[Done], then: Callable[[], object]) -> None:
    """Compensate ``records`` one after the other, then call ``then``."""
    if not records:
        then()
        return
    first, rest = records[0], records[1:]
    _compensate_one(engine, first, lambda: _compensate_all(engine, rest, then))


def _compensate_one(engine: Engine, record: Done, then: Callable[[], object]) -> None:
    """Run one activity's compensation: its handler; for a sub-process without one, its
    compensation event sub-process, else its own completed activities in reverse."""
    handler = record.scope.plan.compensations.get(record.node.id)
    if handler is not None:
        place = _compensation_scope(engine, record.scope, record.frame, then)
        engine.push(engine.new_token(place, handler), handler)
        return
    child = record.child
    esp = child.plan.compensation_handler if child is not None else None
    if child is None or esp is None:
        _compensate_all(engine, _take_done(child, "") if child is not None else [], then)
        return
    place = _compensation_scope(engine, child, child.frame, then)
    place.done = child.done  # what a compensation throw inside the handler compensates
    holder = engine.new_token(place, esp)
    engine.activities.begin(holder, esp.label)
    assert esp.child is not None
    inner = engine.open_scope(esp.child, place, holder)
    start = esp.child.triggered_starts[0]
    caught(engine, engine.new_token(inner, start), start, None)


def _compensation_scope(
    engine: Engine, scope: RunScope, frame: Frame | None, then: Callable[[], object]
) -> RunScope:
    """A scope beside ``scope`` (its plan, its frame) for a compensation to run in;
    ``then`` runs when its last token is gone."""
    place = RunScope(scope.plan, scope, None)
    engine.compensating.add(place)

    def closed() -> None:
        engine.compensating.discard(place)
        then()

    place.frame, place.on_close = frame, closed
    return place


def _take_done(scope: RunScope, activity: str) -> list[Done]:
    """The completed activities of ``scope`` to compensate (``activity``'s instances only,
    when named), the last completed first; they are compensated once, so they leave it."""
    taken = [d for d in scope.done if not activity or d.node.id == activity]
    scope.done = [d for d in scope.done if d not in taken]
    return taken[::-1]
