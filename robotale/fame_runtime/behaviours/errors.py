"""BPMN errors and escalations thrown inside a process: handed to the nearest boundary event
or event sub-process that catches them, innermost first (BPMN 2.0 section 10.5.6); an error
nobody catches ends the process instance."""

from __future__ import annotations

from typing import TYPE_CHECKING

from robotale.fame_runtime.behaviours.boundaries import boundary_fired, event_subprocess
from robotale.fame_runtime.kinds import EventKind
from robotale.fame_runtime.plan import NodePlan
from robotale.fame_runtime.tokens import RunScope, Token, outer

if TYPE_CHECKING:
    from robotale.fame_runtime.engine import Engine


def throw_error(engine: Engine, token: Token, name: str) -> None:
    """Hand a thrown BPMN error to the nearest catcher: the activity's own boundary
    events, then the event sub-processes of each enclosing scope and the boundary events
    of the activity holding it; nobody catching it ends the instance."""
    catcher = _boundary_catcher(outer(token), "error", name)
    if catcher is not None:
        boundary_fired(engine, outer(token), catcher, None)
        return
    if not _catch_above(engine, token, "error", name):
        engine.fail(
            token,
            f"robot {engine.robot.name}: error {name!r} thrown at {token.node.node.describe()} "
            "was not caught; the process instance ended",
        )


def escalate(engine: Engine, token: Token, node: NodePlan) -> bool:
    """Throw an escalation (tagged as the throwing event); True when the thrower goes on
    (nobody caught it, or a non-interrupting catcher did)."""
    throw = node.throw
    assert throw is not None  # the deployer gives every throwing node what it throws
    engine.tag.pair(throw.label)
    _catch_above(engine, token, "escalation", throw.topic)
    return token.alive


def script_limit(engine: Engine, token: Token, node: NodePlan, what: str) -> None:
    """A script ran out of time or memory: a model error, not a BPMN error (no boundary
    event may catch it), that ends the robot's instance."""
    engine.fail(
        token,
        f"robot {engine.robot.name}: script task {node.node.describe()} {what}; the process "
        "instance ended (a model error: no boundary event catches it)",
    )


def _catch_above(engine: Engine, token: Token, kind: str, name: str) -> bool:
    """Hand an error or escalation thrown at ``token`` to the event sub-processes of each
    enclosing scope and the boundary events of the activity holding it, innermost first;
    False when nobody catches it."""
    scope: RunScope | None = token.scope
    while scope is not None:
        esp = _esp_catcher(scope, kind, name)
        if esp is not None:
            assert esp.child is not None
            interrupting = (
                kind == EventKind.ERROR or esp.child.triggered_starts[0].node.interrupting
            )
            event_subprocess(engine, scope, esp, None, interrupting=interrupting)
            return True
        if scope.holder is not None:
            holder = outer(scope.holder)
            catcher = _boundary_catcher(holder, kind, name)
            if catcher is not None:
                boundary_fired(engine, holder, catcher, None)
                return True
        scope = scope.parent
    return False


def _boundary_catcher(token: Token, kind: str, name: str) -> NodePlan | None:
    for boundary in token.node.boundaries:
        trigger = boundary.trigger
        if trigger is not None and trigger.kind == kind and trigger.topic in ("", name):
            return boundary
    return None


def _esp_catcher(scope: RunScope, kind: str, name: str) -> NodePlan | None:
    for esp in scope.plan.event_subprocesses:
        assert esp.child is not None
        trigger = esp.child.triggered_starts[0].trigger
        if (
            esp.id in scope.armed
            and trigger is not None
            and trigger.kind == kind
            and trigger.topic in ("", name)
        ):
            return esp
    return None
