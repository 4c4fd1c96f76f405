"""``robotale fame check``: can every pool run, and can every publisher talk to every
subscriber of its topic (C-QoS, thesis 4.2)?

Signal throw events are publishers and signal catch events subscribers (guideline G3),
those of the building blocks a pool calls included. For every publisher and subscriber of the
same topic the ROS 2 QoS rules decide (:func:`~robotale.fame_runtime.qos.incompatibilities`),
and a message type that differs on the two sides is reported too.
"""

from __future__ import annotations

from collections import defaultdict
from collections.abc import Collection
from dataclasses import dataclass, field

from robotale.fame_runtime.labels import THROWING, catches, signal_topic
from robotale.fame_runtime.library import Library, resolve_call
from robotale.fame_runtime.model import Definitions, Node, Process
from robotale.fame_runtime.plan import problems
from robotale.fame_runtime.qos import DEFAULT_QOS, QoS, pair_problems


@dataclass(frozen=True, slots=True)
class Endpoint:
    """A signal event as a publisher or subscriber of a topic."""

    pool: str
    process: str
    element: str  # the event's id (and name)
    topic: str
    msgtype: str
    qos: QoS
    line: int

    def describe(self) -> str:
        return f"{self.pool} {self.element}"


@dataclass(frozen=True, slots=True)
class Pairing:
    """One publisher and one subscriber of a topic, and why they cannot talk (if so)."""

    publisher: Endpoint
    subscriber: Endpoint
    reasons: tuple[str, ...]

    @property
    def compatible(self) -> bool:
        return not self.reasons


@dataclass(slots=True)
class Report:
    file: str
    pools: list[str] = field(default_factory=list)
    problems: list[str] = field(default_factory=list)  # "<pool>: <element> <why>"
    pairs: list[Pairing] = field(default_factory=list)
    notes: list[str] = field(default_factory=list)
    warnings: list[str] = field(default_factory=list)  # silent choices of the parser

    @property
    def ok(self) -> bool:
        return not self.problems and all(p.compatible for p in self.pairs)


def check(
    definitions: Definitions, *, skills: Collection[str] = (), library: Library | None = None
) -> Report:
    """Structure (what the engine would refuse) and QoS compatibility of a collaboration."""
    report = Report(str(definitions.file), warnings=list(definitions.warnings))
    for pool, process in definitions.pools():
        report.pools.append(pool.name + (" (multi-instance)" if pool.multi_instance else ""))
        report.problems += [
            f"{pool.name}: {p}" for p in problems(process, skills=skills, library=library)
        ]
    publishers, subscribers = endpoints(definitions, skills=skills, library=library)
    for topic in sorted(set(publishers) | set(subscribers)):
        report.pairs += [
            Pairing(pub, sub, tuple(_reasons(pub, sub)))
            for pub in publishers[topic]
            for sub in subscribers[topic]
        ]
        report.notes += _lonely(topic, publishers[topic], subscribers[topic])
    return report


def endpoints(
    definitions: Definitions, *, skills: Collection[str] = (), library: Library | None = None
) -> tuple[dict[str, list[Endpoint]], dict[str, list[Endpoint]]]:
    """Every pool's signal publishers and subscribers (building blocks included), by topic:
    what a DDS participant declares before its robot starts."""
    publishers: dict[str, list[Endpoint]] = defaultdict(list)
    subscribers: dict[str, list[Endpoint]] = defaultdict(list)
    for pool, process in definitions.pools():
        for node, owner in _signal_events(process, skills, library):
            endpoint = _endpoint(pool.name, owner, node)
            if node.kind in THROWING:
                publishers[endpoint.topic].append(endpoint)
            elif catches(node):
                subscribers[endpoint.topic].append(endpoint)
    return publishers, subscribers


def _signal_events(process: Process, skills: Collection[str], library: Library | None):
    """The signal events of a process and of every process it calls (once each)."""
    seen: set[int] = set()
    stack = [process]
    while stack:
        current = stack.pop()
        if id(current) in seen:
            continue
        seen.add(id(current))
        for node in current.walk():
            if node.event_kind == "signal" and signal_topic(node):
                yield node, current
            if node.kind == "callActivity" and node.called_element not in skills:
                called = node.embedded_process or resolve_call(
                    node.called_element, current, library
                )
                if called is not None:
                    stack.append(called)


def _endpoint(pool: str, process: Process, node: Node) -> Endpoint:
    message = node.message
    msgtype = message.msgtype if message else ""
    qos = message.qos if message else DEFAULT_QOS
    return Endpoint(pool, process.id, node.describe(), signal_topic(node), msgtype, qos, node.line)


def _reasons(publisher: Endpoint, subscriber: Endpoint) -> list[str]:
    return pair_problems(publisher.qos, subscriber.qos, publisher.msgtype, subscriber.msgtype)


def _lonely(topic: str, publishers: list[Endpoint], subscribers: list[Endpoint]) -> list[str]:
    if not publishers:
        who = ", ".join(sorted({s.describe() for s in subscribers}))
        return [f"{topic}: caught by {who} but thrown by no pool (published from outside?)"]
    if not subscribers:
        who = ", ".join(sorted({p.describe() for p in publishers}))
        return [f"{topic}: thrown by {who} but caught by no pool"]
    return []
