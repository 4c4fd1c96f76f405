"""Events on a sequence flow (BPMN 2.0 section 10.5): start events, intermediate catch and
throw events, end events, boundary events once fired; send and receive tasks behave like a
message throw and catch."""

from __future__ import annotations

from typing import TYPE_CHECKING

from robotale.fame_runtime.behaviours.boundaries import arm_boundaries
from robotale.fame_runtime.behaviours.catching import waker
from robotale.fame_runtime.behaviours.compensation import throw_compensation
from robotale.fame_runtime.behaviours.errors import escalate, throw_error
from robotale.fame_runtime.kinds import EventKind
from robotale.fame_runtime.plan import NodePlan
from robotale.fame_runtime.tags import SEND, Lifecycle, payload_text
from robotale.fame_runtime.tokens import Token

if TYPE_CHECKING:
    from robotale.fame_runtime.engine import Engine


def run_start(engine: Engine, token: Token, node: NodePlan) -> NodePlan | None:
    return engine.follow(token, engine.taken(node, first=False))


def run_boundary(engine: Engine, token: Token, node: NodePlan) -> NodePlan | None:
    return engine.follow(token, engine.taken(node, first=False))


def run_event_subprocess(engine: Engine, token: Token, node: NodePlan) -> NodePlan | None:
    return None  # never entered by a sequence flow; boundaries.event_subprocess starts it


def run_catch(engine: Engine, token: Token, node: NodePlan) -> NodePlan | None:
    assert node.trigger is not None  # the deployer gives every catching node its trigger
    token.waits.append(engine.triggers.arm(node.trigger, waker(engine, token, node)))
    arm_boundaries(engine, token, node)  # a receive task may have boundary events
    return None


def run_pass(engine: Engine, token: Token, node: NodePlan) -> NodePlan | None:
    """An intermediate throw event or a send task: throw, then go on."""
    kind = node.throw.kind if node.throw is not None else EventKind.NONE
    if kind == EventKind.COMPENSATE:
        if not throw_compensation(engine, token, node, lambda: engine.go_on(token, node)):
            return None  # it goes on once the compensation is done
    elif kind == EventKind.ESCALATION:
        if not escalate(engine, token, node):
            return None  # an interrupting catcher cancelled the thrower
    elif kind != EventKind.NONE:
        publish(engine, node)
    return engine.follow(token, engine.taken(node, first=False))


def run_end(engine: Engine, token: Token, node: NodePlan) -> NodePlan | None:
    throw = node.throw
    kind = throw.kind if throw is not None else EventKind.NONE
    if kind in (EventKind.SIGNAL, EventKind.MESSAGE):
        publish(engine, node)
    if kind == EventKind.ERROR:
        assert throw is not None
        throw_error(engine, token, throw.topic)  # the catching event is tagged
        return None
    if kind == EventKind.ESCALATION and not escalate(engine, token, node):
        return None
    if kind == EventKind.COMPENSATE and not throw_compensation(
        engine, token, node, lambda: engine.consume(token)
    ):
        return None  # it ends once the compensation is done
    engine.consume(token)
    return None


def run_terminate(engine: Engine, token: Token, node: NodePlan) -> NodePlan | None:
    engine.kill_scope(token.scope, safe=True)
    return None


def publish(engine: Engine, node: NodePlan) -> None:
    """Send a signal or message on the bus, tagged as sent."""
    throw = node.throw
    assert throw is not None
    data = engine.data.payload(node)
    msg_id = engine.tag.new_msg_id()
    payload = payload_text(data)
    engine.tag(throw.label, Lifecycle.START, msg_id, SEND, payload)
    engine.bus.publish(
        throw.topic,
        data,
        msgtype=throw.msgtype,
        sender=engine.robot.name,
        msg_id=msg_id,
        qos=throw.qos,
    )
    engine.tag(throw.label, Lifecycle.COMPLETE, msg_id, SEND, payload)
