"""What a BPMN element is called in a log: the one place that decides it.

The engine tags every element it runs with :func:`element_label`; conformance labels its
Petri net transitions with it and the Model page finds elements in a log by it, so a log made
by the engines and the model always agree. The facts the label is made of live here too:
which element kinds catch (:data:`~robotale.fame_runtime.kinds.CATCHING`) and throw
(:data:`~robotale.fame_runtime.kinds.THROWING`), the topic a signal
event uses (:func:`signal_name`, :func:`signal_topic`) and the error an error event names
(:func:`error_name`).
"""

from __future__ import annotations

import re

from robotale.fame_runtime.kinds import CATCHING, MESSAGE_TASKS, EventKind
from robotale.fame_runtime.kinds import THROWING as THROWING  # read here too (one object)
from robotale.fame_runtime.model import Node

#: how a message event's label ends, as in the thesis' logs: ``!`` sends, ``?`` receives
SEND, RECEIVE = "!", "?"

_CAMEL = re.compile(r"([a-z0-9])([A-Z])")
_NOT_WORD = re.compile(r"[^0-9a-zA-Z]+")


def activity_label(name: str | None, element_id: str = "") -> str:
    """The activity a name is tagged as (and looked up by in conformance).

    Lower snake case of the name, camel case split and the message suffix kept:
    ``Take Off`` -> ``take_off``, ``ReturnToBase`` -> ``return_to_base``, ``weed_position!``
    stays. An element without a name is tagged with its id.
    """
    text = (name or "").strip()
    if not text:
        return element_id
    suffix = text[-1] if text[-1] in SEND + RECEIVE else ""
    words = _CAMEL.sub(r"\1_\2", text.rstrip(SEND + RECEIVE))
    return _NOT_WORD.sub("_", words).strip("_").lower() + suffix


def catches(node: Node) -> bool:
    """Whether ``node``'s event definition waits for something rather than being thrown."""
    return node.kind in CATCHING


def signal_name(node: Node) -> str:
    """The topic name of a signal event: the event's name (the thesis correlates by it), else
    the referenced signal's; without the thesis' ``!``/``?`` suffix."""
    name = (node.name or (node.event.ref_name if node.event else "")).strip()
    return "_".join(name.rstrip(SEND + RECEIVE).split())


def signal_topic(node: Node) -> str:
    """The topic a signal event publishes or subscribes to ("" when it names no signal)."""
    name = signal_name(node)
    return name if name.startswith("/") or not name else f"/{name}"


def error_name(node: Node) -> str:
    """The error an error event throws or catches ("" catches any): the referenced error's
    name, else the event's name."""
    event = node.event
    name = (event.ref_name if event else "") or node.name
    return "_".join(name.strip().split())


def message_name(node: Node) -> str:
    """The name of the message a message event or send/receive task sends or waits for: the
    referenced message's name, else the element's name; without ``!``/``?``."""
    event = node.event
    name = ((event.ref_name if event else "") or node.name).strip()
    return "_".join(name.rstrip(SEND + RECEIVE).split())


def message_topic(pool_namespace: str, node: Node) -> str:
    """The point-to-point topic of a message: ``/<receiving pool>/<message>`` ("" when the
    message has no name)."""
    name = message_name(node).lstrip("/")
    return f"/{pool_namespace}/{name}" if name and pool_namespace else ""


def escalation_name(node: Node) -> str:
    """The escalation an escalation event throws or catches ("" catches any): the referenced
    escalation's name (or code), else the event's name."""
    event = node.event
    name = (event.ref_name if event else "") or node.name
    return "_".join(name.strip().split())


def element_label(node: Node) -> str:
    """The activity the engine tags ``node`` with: a signal or message event is its signal or
    message with ``!`` (thrown) or ``?`` (caught), an error or escalation event its error or
    escalation, a send or receive task, like anything else, its name."""
    if node.kind in MESSAGE_TASKS:
        suffix = RECEIVE if catches(node) else SEND
        return activity_label(node.name or message_name(node) + suffix, node.id)
    if node.event_kind in (EventKind.SIGNAL, EventKind.MESSAGE):
        suffix = RECEIVE if catches(node) else SEND
        name = signal_name(node) if node.event_kind == EventKind.SIGNAL else message_name(node)
        return activity_label(name + suffix, node.id)
    if node.event_kind == EventKind.ERROR:
        return activity_label(error_name(node), node.id)
    if node.event_kind == EventKind.ESCALATION:
        return activity_label(escalation_name(node), node.id)
    return activity_label(node.name, node.id)
