"""Boundary events and event sub-processes: armed while their activity or scope runs; when
one fires, an interrupting one cancels what it interrupts first (BPMN 2.0 sections 10.5.4 and
10.3.5)."""

from __future__ import annotations

from collections.abc import Callable
from typing import TYPE_CHECKING, Any

from robotale.fame_runtime.behaviours.catching import caught, received
from robotale.fame_runtime.bus import Envelope
from robotale.fame_runtime.kinds import EventKind
from robotale.fame_runtime.plan import NodePlan
from robotale.fame_runtime.tokens import RunScope, Token, nothing

if TYPE_CHECKING:
    from robotale.fame_runtime.engine import Engine


def arm_boundaries(engine: Engine, token: Token, node: NodePlan) -> None:
    """Arm the boundary events of ``token``'s activity at ``node`` until it ends."""
    depth = token.scope.depth + 0.5  # inside the scope, around the activity
    for boundary in node.boundaries:
        trigger = boundary.trigger
        assert trigger is not None  # the deployer gives every boundary event its trigger
        if trigger.kind == EventKind.ESCALATION:
            continue  # found when an escalation is thrown inside (see errors.escalate)
        repeat = not boundary.node.cancel_activity
        fire = _boundary_fire(engine, token, boundary)
        token.boundaries.append(engine.triggers.arm(trigger, fire, repeat=repeat, depth=depth))


def _boundary_fire(
    engine: Engine, token: Token, boundary: NodePlan
) -> Callable[[Envelope | None], None]:
    generation = token.generation

    def fire(envelope: Envelope | None) -> None:
        if token.alive and token.generation == generation:
            boundary_fired(engine, token, boundary, envelope)

    return fire


def boundary_fired(
    engine: Engine, token: Token, boundary: NodePlan, envelope: Envelope | None
) -> None:
    """``boundary`` of ``token``'s activity fired: an interrupting one cancels the activity;
    a new token leaves by the boundary event."""
    if boundary.node.cancel_activity:
        scope = token.scope
        with engine.activities.interrupting():
            engine.cancel(token)
        token = engine.new_token(scope, boundary)
    else:
        token = engine.new_token(token.scope, boundary)
    caught(engine, token, boundary, envelope)


def arm_event_subprocess(engine: Engine, scope: RunScope, esp: NodePlan) -> None:
    """Arm the start of event sub-process ``esp`` while ``scope`` runs."""
    assert esp.child is not None  # the deployer gives every sub-process its content
    start = esp.child.triggered_starts[0]
    trigger = start.trigger
    assert trigger is not None
    interrupting = start.node.interrupting
    if trigger.kind == EventKind.COMPENSATE:
        return  # it runs when its scope is compensated (see compensation.compensate_one)
    if trigger.kind == EventKind.ESCALATION:  # nothing to wait for outside the engine
        scope.armed[esp.id] = nothing
        return

    def fire(envelope: Envelope | None) -> None:
        if not scope.ended and esp.id in scope.armed:
            event_subprocess(engine, scope, esp, envelope, interrupting=interrupting)

    scope.armed[esp.id] = engine.triggers.arm(
        trigger, fire, repeat=not interrupting, depth=scope.depth
    )


def event_subprocess(
    engine: Engine,
    scope: RunScope,
    esp: NodePlan,
    envelope: Envelope | None,
    *,
    interrupting: bool,
    triggered: bool = True,
) -> None:
    """Start event sub-process ``esp`` in ``scope`` (an interrupting one cancels the rest of
    the scope first); ``triggered``: its start event is tagged as caught.

    The catch is tagged before the sub-process starts, as for a boundary event: the trigger
    is what starts it, and the thesis' log has the trigger (``low_battery``) right after what
    it interrupted, so a directly-follows graph draws ``explore -> low_battery``.
    """
    if interrupting and esp.id in scope.armed:
        scope.armed.pop(esp.id)()  # an interrupting handler runs once per scope
    if esp is scope.plan.safe_state:
        scope.safe = True
    holder = engine.new_token(scope, esp)
    if interrupting:
        with engine.activities.interrupting():
            for token in list(scope.tokens):
                if token is not holder:
                    engine.cancel(token)
    assert esp.child is not None
    start = esp.child.triggered_starts[0]
    values = _caught_start(engine, holder, start, envelope) if triggered else None
    engine.activities.begin(holder, esp.label)
    child = engine.open_scope(esp.child, scope, holder)
    token = engine.new_token(child, start)
    if values is not None:
        engine.enter_token(token)
        engine.data.outputs(start, values)
    engine.go_on(token, start)


def _caught_start(
    engine: Engine, holder: Token, start: NodePlan, envelope: Envelope | None
) -> dict[str, Any]:
    """Tag the start event of ``holder``'s event sub-process as caught; the message's fields
    (for the start event's outputs once the sub-process runs)."""
    engine.enter_token(holder)
    return received(engine, start, envelope)
