"""Gateways (BPMN 2.0 sections 10.6 and 13.3): exclusive and inclusive splits by their
conditions, parallel joins counting one token per incoming flow, inclusive joins waiting while
a token may still arrive, and event-based gateways waiting for the first of their events."""

from __future__ import annotations

from typing import TYPE_CHECKING

from robotale.errors import ModelError
from robotale.fame_runtime.behaviours.catching import waker
from robotale.fame_runtime.kinds import Run
from robotale.fame_runtime.plan import NodePlan, reachable_flows
from robotale.fame_runtime.tokens import RunScope, Token

if TYPE_CHECKING:
    from robotale.fame_runtime.engine import Engine


def run_exclusive(engine: Engine, token: Token, node: NodePlan) -> NodePlan | None:
    return _split(engine, token, node, first=True)


def run_parallel(engine: Engine, token: Token, node: NodePlan) -> NodePlan | None:
    if len(node.incoming) > 1 and not _joined(token, node):
        return None
    return engine.follow(token, list(node.outgoing))


def run_inclusive(engine: Engine, token: Token, node: NodePlan) -> NodePlan | None:
    if len(node.incoming) > 1:
        token.scope.joins.setdefault(node.id, []).append(token)
        engine.inclusive.add(token.scope)
        return None
    return _split(engine, token, node, first=False)


def run_event_based(engine: Engine, token: Token, node: NodePlan) -> NodePlan | None:
    for flow in node.outgoing:
        target = flow.target
        if target.trigger is not None:
            token.waits.append(engine.triggers.arm(target.trigger, waker(engine, token, target)))
    return None


def recheck_joins(engine: Engine) -> None:
    """Let the inclusive joins go on that no token can reach any more but those waiting."""
    for scope in list(engine.inclusive):
        for node_id, waiting in list(scope.joins.items()):
            node = scope.plan.nodes[node_id]
            if node.behaviour == Run.INCLUSIVE_GATEWAY and waiting and _may_go(scope, node):
                _merge_inclusive(engine, scope, node, waiting)
        if not any(scope.joins.values()):
            engine.inclusive.discard(scope)


def _split(engine: Engine, token: Token, node: NodePlan, *, first: bool) -> NodePlan | None:
    """An exclusive (``first``) or inclusive split; no flow to take is a model error."""
    flows = engine.taken(node, first=first)
    if not flows:
        raise ModelError(
            f"robot {engine.robot.name}: {node.node.kind} {node.node.describe()} has no "
            "outgoing flow whose condition holds and no default flow"
        )
    return engine.follow(token, flows)


def _joined(token: Token, node: NodePlan) -> bool:
    """A parallel join: True (with one token going on) once every incoming flow has a
    token waiting."""
    waiting = token.scope.joins.setdefault(node.id, [])
    waiting.append(token)
    arrived = {t.flow for t in waiting}
    if not arrived.issuperset(node.incoming):
        return False
    for flow_id in node.incoming:
        first = next(t for t in waiting if t.flow == flow_id)
        waiting.remove(first)
        if first is not token:
            first.alive = False
            token.scope.tokens.discard(first)
    return True


def _may_go(scope: RunScope, node: NodePlan) -> bool:
    """An inclusive join fires when no other token can still reach an incoming flow that
    has no token yet."""
    arrived = {t.flow for t in scope.joins[node.id]}
    missing = set(node.incoming) - arrived
    for token in scope.tokens:
        if token.node is node and token in scope.joins[node.id]:
            continue
        if missing & reachable_flows(token.node):
            return False
    return True


def _merge_inclusive(engine: Engine, scope: RunScope, node: NodePlan, waiting: list[Token]) -> None:
    survivor, *others = waiting
    scope.joins[node.id] = []
    for other in others:
        other.alive = False
        scope.tokens.discard(other)
    next_node = _split(engine, survivor, node, first=False)
    if next_node is not None:
        engine.push(survivor, next_node)
