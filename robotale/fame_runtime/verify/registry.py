"""The verifier's view of the deployed plans: every node and scope numbered (a state holds
numbers), the conditions as written, the variables a test can depend on, the timers' durations.
"""

from __future__ import annotations

import ast

from robotale.fame_runtime.kinds import EventKind, Run
from robotale.fame_runtime.model import Expression, Process
from robotale.fame_runtime.plan import FlowPlan, NodePlan, ScopePlan
from robotale.fame_runtime.verify.values import (
    condition_names,
    script_effect,
)

ElementKey = tuple[str, str]  # (process, element id)


def element_key(node: NodePlan) -> ElementKey:
    return (node.scope.process.id, node.node.id)


# -- the registry: plans <-> numbers -------------------------------------------------------------


class Registry:
    """Numbers for every node and scope plan of the robots' plans (states hold numbers)."""

    def __init__(self) -> None:
        self.nodes: list[NodePlan] = []
        self.scopes: list[ScopePlan] = []
        self._node_ids: dict[int, int] = {}
        self._scope_ids: dict[int, int] = {}
        self._conditions: dict[tuple[str, str], Expression | None] = {}
        self._processes: set[int] = set()

    def add_scope(self, plan: ScopePlan) -> None:
        if id(plan) in self._scope_ids:
            return
        self._add_conditions(plan.process)
        self._scope_ids[id(plan)] = len(self.scopes)
        self.scopes.append(plan)
        for node in [*plan.nodes.values(), *plan.event_subprocesses]:
            self.add_node(node)

    def add_node(self, node: NodePlan) -> None:
        if id(node) in self._node_ids:
            return
        self._node_ids[id(node)] = len(self.nodes)
        self.nodes.append(node)
        for boundary in node.boundaries:
            self.add_node(boundary)
        if node.child is not None:
            self.add_scope(node.child)
        if node.loop is not None:
            self.add_node(node.loop.body)

    def _add_conditions(self, process: Process) -> None:
        """The conditions of the process's sequence flows as written (the plan keeps them
        compiled, and a JavaScript one wrapped in a function)."""
        if id(process) in self._processes:
            return
        self._processes.add(id(process))
        scopes = [process, *(n.scope for n in process.walk() if n.scope is not None)]
        for scope in scopes:
            for flow in scope.flows.values():
                self._conditions[(process.id, flow.id)] = flow.condition

    def conditions(self) -> list[Expression | None]:
        """Every sequence flow condition as written."""
        return list(self._conditions.values())

    def condition(self, flow: FlowPlan) -> Expression | None:
        """The condition of ``flow`` as written (None: it always holds)."""
        if flow.condition is None:
            return None
        process = flow.target.scope.process
        written = self._conditions.get((process.id, flow.id))
        return written or Expression("", flow.condition.language, flow.id)  # unknown

    def node_id(self, node: NodePlan) -> int:
        return self._node_ids[id(node)]

    def scope_id(self, plan: ScopePlan | None) -> int:
        return -1 if plan is None else self._scope_ids[id(plan)]


def relevant_names(registry: Registry) -> frozenset[str]:
    """The variables a test can depend on: those conditions read, and those the values
    assigned to them read, and so on. Only these are kept in a state: the others cannot tell
    two states apart."""
    reads: set[str] = set()
    feeds: dict[str, set[str]] = {}  # variable -> the variables its assigned values read

    def condition(expression: Expression | None) -> None:
        if expression is not None:
            reads.update(condition_names(expression.text, expression.language))

    def assigned(name: str, text: object) -> None:
        if isinstance(text, str):
            inner = text.strip().removeprefix("${").removesuffix("}")
            feeds.setdefault(name, set()).update(condition_names(inner, "python"))

    for expression in registry.conditions():
        condition(expression)
    for node in registry.nodes:
        event = node.node.event
        condition(event.condition if event is not None else None)
        if node.node.loop is not None:
            condition(node.node.loop.condition)
        for data_object in [*node.data_inputs, *node.data_outputs]:
            for name, text in data_object.parameters.items():
                assigned(name, text)
        for name, value in {**node.node.inputs, **node.node.outputs}.items():
            assigned(name, value)
        script = node.node.script
        if script is not None:
            for name, tree in script_effect(script.text, script.language).sets:
                feeds.setdefault(name, set()).update(
                    n.id for n in ast.walk(tree) if isinstance(n, ast.Name)
                )
    relevant: set[str] = set()
    pending = list(reads)
    while pending:
        name = pending.pop()
        if name not in relevant:
            relevant.add(name)
            pending.extend(feeds.get(name, ()))
    return frozenset(relevant)


def timer_seconds(catcher: NodePlan) -> float | None:
    """How long after arming a timer first fires (None: a date, or not known before)."""
    spec = catcher.trigger.timer if catcher.trigger is not None else None
    if spec is None or "${" in spec.text or spec.kind == "timeDate":
        return None
    if getattr(spec, "at", None) is not None:
        return None
    return spec.interval


#: the timers at a node while it runs and while it waits, with their seconds
Timers = tuple[list[tuple[NodePlan, float | None]], list[tuple[NodePlan, float | None]]]


def node_timers(node: NodePlan) -> Timers:
    """The timers a token at ``node`` waits on while the node runs (its boundary events)
    and while it waits there (a catch event's or an event-based gateway's too)."""
    catchers = list(node.boundaries)
    running = [(c, timer_seconds(c)) for c in catchers if _is_timer(c)]
    if node.behaviour == Run.CATCH:
        catchers.append(node)
    if node.behaviour == Run.EVENT_BASED_GATEWAY:
        catchers += [f.target for f in node.outgoing]
    return running, [(c, timer_seconds(c)) for c in catchers if _is_timer(c)]


def _is_timer(node: NodePlan) -> bool:
    return node.trigger is not None and node.trigger.kind == EventKind.TIMER
