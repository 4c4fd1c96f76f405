"""What happens when a catching event fires -- an intermediate catch event, a boundary event,
a start event with a trigger, a receive task, an event-based gateway's event: it is tagged,
its message goes to the variables and its token moves on."""

from __future__ import annotations

from collections.abc import Callable
from typing import TYPE_CHECKING, Any

from robotale.fame_runtime.bus import Envelope
from robotale.fame_runtime.kinds import EventKind
from robotale.fame_runtime.plan import NodePlan
from robotale.fame_runtime.tags import RECEIVE, payload_text
from robotale.fame_runtime.tokens import Token

if TYPE_CHECKING:
    from robotale.fame_runtime.engine import Engine


def waker(engine: Engine, token: Token, node: NodePlan) -> Callable[[Envelope | None], None]:
    """What fires when ``token``'s catching event at ``node`` is triggered (stale once the
    token has moved on)."""
    generation = token.generation

    def fire(envelope: Envelope | None) -> None:
        if token.alive and token.generation == generation:
            engine.disarm(token)
            caught(engine, token, node, envelope)

    return fire


def caught(engine: Engine, token: Token, node: NodePlan, envelope: Envelope | None) -> None:
    """A catching event fired for ``token``: tag it, store the message, move on."""
    engine.enter_token(token)
    values = received(engine, node, envelope)
    engine.data.outputs(node, values)
    token.node = node
    engine.go_on(token, node)


def received(engine: Engine, node: NodePlan, envelope: Envelope | None) -> dict[str, Any]:
    """Tag a fired catching event; a message's data goes to the variables."""
    trigger = node.trigger
    assert trigger is not None  # the deployer gives every catching node its trigger
    if envelope is None or trigger.kind != EventKind.SIGNAL:
        engine.tag.pair(trigger.label)
        return {}
    payload = payload_text(envelope.data)
    engine.tag.pair(trigger.label, envelope.msg_id, RECEIVE, payload)
    return engine.data.received(trigger.topic, envelope.data)
