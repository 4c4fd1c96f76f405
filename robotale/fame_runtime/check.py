"""``robotale fame check``: can every pool run, and can every publisher talk to every
subscriber of its topic (C-QoS, thesis 4.2)?

Signal throw events are publishers and signal catch events subscribers (guideline G3),
those of the building blocks a pool calls included. For every publisher and subscriber of the
same topic the ROS 2 QoS rules decide (:func:`~robotale.fame_runtime.qos.incompatibilities`),
and a message type that differs on the two sides is reported too.
"""

from __future__ import annotations

from collections import defaultdict
from collections.abc import Collection, Iterator
from dataclasses import dataclass, field
from pathlib import Path

from lxml import etree

from robotale.fame_runtime.kinds import GATEWAYS, THROWING, EventKind, Kind
from robotale.fame_runtime.labels import catches, signal_topic
from robotale.fame_runtime.library import Library, resolve_call
from robotale.fame_runtime.model import Definitions, Node, Problem, Process, Scope
from robotale.fame_runtime.plan import findings
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
    #: what cannot be read or run, reading and deploying together, with the pool it is in
    found: list[tuple[str, Problem]] = field(default_factory=list)
    pairs: list[Pairing] = field(default_factory=list)
    notes: list[str] = field(default_factory=list)
    warnings: list[str] = field(default_factory=list)  # silent choices of the parser

    @property
    def problems(self) -> list[str]:
        """Each problem as "<pool>: <sentence>" (the file's own: the sentence alone)."""
        return [f"{pool}: {p.sentence}" if pool else p.sentence for pool, p in self.found]

    @property
    def ok(self) -> bool:
        return not self.found and all(p.compatible for p in self.pairs)


def check(
    definitions: Definitions, *, skills: Collection[str] = (), library: Library | None = None
) -> Report:
    """Structure (what the engine would refuse) and QoS compatibility of a collaboration."""
    report = Report(str(definitions.file), warnings=list(definitions.warnings))
    report.found += [("", p) for p in definitions.problems]
    report.found += [("", p) for p in shared_ids(definitions.file)]
    for pool, process in definitions.pools():
        report.pools.append(pool.name + (" (multi-instance)" if pool.multi_instance else ""))
        found = findings(process, skills=skills, library=library)
        found += [
            Problem(str(definitions.file), process.line, process.id, sentence)
            for sentence in progress_problems(process)
        ]
        report.found += [(pool.name, definitions.placed(p)) for p in found]
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


def _signal_events(
    process: Process, skills: Collection[str], library: Library | None
) -> Iterator[tuple[Node, Process]]:
    """The signal events of a process and of every process it calls (once each)."""
    seen: set[int] = set()
    stack = [process]
    while stack:
        current = stack.pop()
        if id(current) in seen:
            continue
        seen.add(id(current))
        for node in current.walk():
            if node.event_kind == EventKind.SIGNAL and signal_topic(node):
                yield node, current
            if node.kind == Kind.CALL_ACTIVITY and node.called_element not in skills:
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


# -- flows that can never complete -------------------------------------------------------------


def progress_problems(process: Process) -> list[str]:
    """Loops made only of gateways (a token there does nothing, forever) and parallel joins
    that wait for a token only they can let through (a deadlock), in every (sub-)scope."""
    found: list[str] = []
    for scope in _scopes(process):
        graph = _successors(scope)
        found += _gateway_loops(scope, graph) + _deadlocked_joins(scope, graph)
    return found


def _scopes(scope: Scope) -> list[Scope]:
    scopes = [scope]
    for node in scope.nodes.values():
        if node.scope is not None:
            scopes += _scopes(node.scope)
    return scopes


def _successors(scope: Scope) -> dict[str, list[str]]:
    """Each node's successors: its sequence flows, and from an activity its boundary events."""
    graph: dict[str, list[str]] = {node: [] for node in scope.nodes}
    for flow in scope.flows.values():
        if flow.source in graph and flow.target in graph:
            graph[flow.source].append(flow.target)
    for node in scope.nodes.values():
        if node.attached_to in graph:
            graph[node.attached_to].append(node.id)
    return graph


def _gateway_loops(scope: Scope, graph: dict[str, list[str]]) -> list[str]:
    gateways = {n for n, node in scope.nodes.items() if node.kind in GATEWAYS}
    only_gateways = {n: [t for t in graph[n] if t in gateways] for n in gateways}
    return [
        f"{_names(scope, loop)} form a loop of gateways only: a token there never reaches a task "
        "or event, so the loop can never progress (add the activity the loop repeats)"
        for loop in _cycles(only_gateways)
    ]


def _deadlocked_joins(scope: Scope, graph: dict[str, list[str]]) -> list[str]:
    """A parallel join waits for a token on every incoming flow; a flow whose source can only
    be reached through the join itself never gets one before the join has fired."""
    incoming: dict[str, list[str]] = defaultdict(list)
    for source, targets in graph.items():
        for target in targets:
            incoming[target].append(source)
    starts = [n for n in graph if not incoming[n]]
    found = []
    for join, node in scope.nodes.items():
        if node.kind != Kind.PARALLEL_GATEWAY or len(incoming[join]) < 2:
            continue
        reached = _reachable(graph, starts, avoid=join)
        stuck = sorted(source for source in incoming[join] if source not in reached)
        if stuck:
            found.append(
                f"{node.describe()} joins in parallel but its flow from {_names(scope, stuck)} "
                "can only carry a token after the join itself has fired: it deadlocks (join "
                "that loop with an exclusive gateway)"
            )
    return found


def _reachable(graph: dict[str, list[str]], starts: list[str], avoid: str) -> set[str]:
    seen = {start for start in starts if start != avoid}
    stack = list(seen)
    while stack:
        for target in graph[stack.pop()]:
            if target != avoid and target not in seen:
                seen.add(target)
                stack.append(target)
    return seen


def _cycles(graph: dict[str, list[str]]) -> list[list[str]]:
    """The strongly connected parts of ``graph`` that hold a cycle (Tarjan, iteratively)."""
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    on_stack: set[str] = set()
    stack: list[str] = []
    cycles = []
    for root in sorted(graph):
        if root in index:
            continue
        work = [(root, iter(graph[root]))]
        index[root] = low[root] = len(index)
        stack.append(root)
        on_stack.add(root)
        while work:
            node, targets = work[-1]
            target = next(targets, None)
            if target is None:
                work.pop()
                if work:
                    low[work[-1][0]] = min(low[work[-1][0]], low[node])
                if low[node] == index[node]:
                    part = []
                    while True:
                        member = stack.pop()
                        on_stack.discard(member)
                        part.append(member)
                        if member == node:
                            break
                    if len(part) > 1 or node in graph[node]:
                        cycles.append(sorted(part))
            elif target not in index:
                index[target] = low[target] = len(index)
                stack.append(target)
                on_stack.add(target)
                work.append((target, iter(graph[target])))
            elif target in on_stack:
                low[node] = min(low[node], index[target])
    return cycles


def _names(scope: Scope, ids: list[str]) -> str:
    return ", ".join(scope.nodes[n].describe() for n in ids)


#: the namespaces of the standard's own elements (model, diagram interchange): vendors'
#: elements elsewhere may carry ids of their own meaning (``<adonis:target id=...>``)
_OMG = "http://www.omg.org/spec/"


def duplicate_ids(file: Path | None) -> list[str]:
    """Element ids given to more than one element of the file: the parser keeps only one of
    them, so a model with two ``start`` ids would look as if it had none."""
    return [p.sentence for p in shared_ids(file)]


def shared_ids(file: Path | None) -> list[Problem]:
    """:func:`duplicate_ids` with where each id is first given. Only the standard's elements
    count: ids on vendor extensions (in ``extensionElements`` or a foreign namespace) are the
    vendor's business."""
    if file is None or not Path(file).is_file():
        return []
    lines: dict[str, list[int]] = defaultdict(list)
    try:
        tree = etree.parse(str(file), etree.XMLParser(resolve_entities=False, no_network=True))
    except etree.XMLSyntaxError:
        return []  # the parser has refused it already
    _standard_ids(tree.getroot(), lines)
    return [
        Problem(
            str(file),
            at[0],
            ident,
            f"the id {ident!r} is given to {len(at)} elements (lines "
            f"{', '.join(map(str, at))}); each element needs its own id",
        )
        for ident, at in sorted(lines.items())
        if len(at) > 1
    ]


def _standard_ids(element: etree._Element, lines: dict[str, list[int]]) -> None:
    stack = [element]
    while stack:
        current = stack.pop()
        if not isinstance(current.tag, str) or not current.tag.startswith("{" + _OMG):
            continue  # a vendor's element: neither it nor its content counts
        if current.tag.endswith("}extensionElements"):
            continue
        if ident := current.get("id"):
            lines[ident].append(current.sourceline or 0)
        stack.extend(reversed(current))
