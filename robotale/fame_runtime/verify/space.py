"""The collaboration's states and the steps between them, as the verifier abstracts them.

A state holds, for every robot, its running instances (the tokens of each scope, nested
through sub-processes, called processes and loop bodies), the variables it tracks (see
:mod:`.values`) and whether its first instance has begun. Everything is immutable and
hashable (:class:`State`), so the explorer can tell a state it has seen before.

A step starts from one thing that can happen in a state -- a robot's first instance begins, a
timer fires, a skill ends, a conditional event whose condition may hold fires, a signal from
outside arrives -- and runs every robot it touches as far as they go without waiting, as the
engines do. Signals are broadcast as on the bus: a throw reaches the catchers armed at that
moment, in every robot, and only those. A test whose value is unknown is a choice; the step is
run once per combination of choices (:class:`Choices`), each giving its own next state.
"""

from __future__ import annotations

import itertools
from collections.abc import Callable, Iterator
from operator import methodcaller
from typing import Any

from robotale.fame_runtime.kinds import EventKind, Run
from robotale.fame_runtime.model import Expression
from robotale.fame_runtime.plan import NodePlan, ScopePlan
from robotale.fame_runtime.verify.registry import (
    Registry,
    Timers,
    node_timers,
    relevant_names,
    timer_seconds,
)
from robotale.fame_runtime.verify.state import Robot, Scope, State, Tok, scopes
from robotale.fame_runtime.verify.values import (
    condition_tree,
    evaluate,
    truth,
)

#: what an event does, given the step (:class:`~.step.Step`) it runs in
Action = Callable[[Any], None]


def _begin_all(step: Any) -> None:  # a Step (whose module imports this one)
    for robot in step.robots:
        step.begin(robot)


def _fire_where_it_is(token: Tok) -> Action:
    """Fire ``token``'s catching event where the token is when the event happens."""
    return lambda step: step.fire(token, token.node, "")


#: tokens one scope may hold: a non-interrupting event firing again beyond it is not explored
TOKEN_CAP = 8
#: instances one robot may run at once: a start event firing beyond it is not explored
INSTANCE_CAP = 2
#: steps one macro step may take: more is a loop that never waits
STEP_CAP = 10_000

#: tags a step that never waits keeps for its trace
BUSY_TAGS = 40

#: how the setter of a value a test implied begins (see Step._assume)
ASSUMED = "assumed at "
#: the arming time of the timers a step arms: after all those of the state before it
NOW = 1 << 30


class Space:
    """The robots of a collaboration, each with its deployed plan; states and steps."""

    def __init__(self, robots: list[tuple[str, ScopePlan]], outside: frozenset[str]) -> None:
        self.registry = Registry()
        self.robots = robots
        self.outside = outside  # signal topics the world may throw at any time
        #: node plan id -> its timers (the plans live as long as the space)
        self._timer_cache: dict[int, Timers] = {}
        for _, plan in robots:
            self.registry.add_scope(plan)
            for start in plan.triggered_starts:
                self.registry.add_node(start)
        self.inclusive = any(n.behaviour == Run.INCLUSIVE_GATEWAY for n in self.registry.nodes)
        self.relevant = relevant_names(self.registry)

    def timers(self, token: Tok) -> list[tuple[NodePlan, float | None]]:
        """The timers ``token`` waits on: its catch event, an event-based gateway's, its
        activity's boundary events."""
        waiting = token.waiting == "wait"
        if not waiting and token.child is None:
            return []
        cached = self._timer_cache.get(id(token.node))
        if cached is None:  # the same for every token at this node: computed once
            cached = self._timer_cache[id(token.node)] = node_timers(token.node)
        return cached[waiting]

    def initial(self) -> State:
        return tuple((False, (), (), ()) for _ in self.robots)

    # -- thaw and freeze -------------------------------------------------------------------------

    def thaw(self, state: State) -> list[Robot]:
        robots = []
        for (name, plan), (begun, instances, variables, later) in zip(
            self.robots, state, strict=True
        ):
            robot = Robot(name, plan, begun, variables=dict(variables), later=set(later))
            robot.instances = [self._thaw_scope(robot, key, None) for key in instances]
            robots.append(robot)
        return robots

    def _thaw_scope(self, robot: Robot, key: tuple[Any, ...], holder: Tok | None) -> Scope:
        scope_id, fired, tokens = key
        plan = None if scope_id < 0 else self.registry.scopes[scope_id]
        scope = Scope(robot, plan, holder)
        scope.fired = set(fired)
        for node_id, flow, waiting, since, child in tokens:
            token = Tok(scope, self.registry.nodes[node_id], flow, waiting)
            token.since = since
            if child:
                token.child = self._thaw_scope(robot, child, token)
            scope.tokens.append(token)
        return scope

    def freeze(self, robots: list[Robot]) -> State:
        # the timers' arming order is all that is kept of time: ranks 1, 2 ... (0: no timer)
        arms = {t.since for r in robots for s in scopes(r) for t in s.tokens if self.timers(t)}
        ranks = {since: rank for rank, since in enumerate(sorted(arms), start=1)}
        return tuple(
            (
                r.begun,
                tuple(sorted(self._freeze_scope(s, ranks) for s in r.instances)),
                tuple(sorted(r.variables.items(), key=lambda item: item[0])),
                tuple(sorted(r.later)),
            )
            for r in robots
        )

    def _freeze_scope(self, scope: Scope, ranks: dict[int, int]) -> tuple[Any, ...]:
        tokens = sorted(
            (
                self.registry.node_id(t.node),
                t.flow,
                t.waiting,
                ranks[t.since] if self.timers(t) else 0,
                self._freeze_scope(t.child, ranks) if t.child is not None else (),
            )
            for t in scope.tokens
        )
        return (self.registry.scope_id(scope.plan), tuple(sorted(scope.fired)), tuple(tokens))

    # -- what can happen -------------------------------------------------------------------------

    def events(self, robots: list[Robot]) -> list[tuple[str, Action]]:
        """Everything that can happen in a state, each with a name and what it does."""
        return list(self._events(robots))

    def event(self, robots: list[Robot], number: int) -> Action:
        """What the ``number``-th of :meth:`events` does (without building the others)."""
        return next(itertools.islice(self._events(robots), number, None))[1]

    def _events(self, robots: list[Robot]) -> Iterator[tuple[str, Action]]:
        self._armed_timers = [
            (t.since, duration, t, catcher)
            for r in robots
            for s in scopes(r)
            for t in s.tokens
            for catcher, duration in self.timers(t)
        ]
        ready = [
            (r, t)
            for r in robots
            for s in scopes(r)
            for t in s.tokens
            if t.waiting in ("ready", "again")
        ]
        if ready:  # a loop's next round comes before anything else can happen
            for robot, token in ready:
                yield (f"{robot.name}: {token.node.label}", methodcaller("resume", token))
            return
        if not all(robot.begun for robot in robots):
            # the engines start together: every first instance runs before any timer fires
            yield ("the mission begins", _begin_all)
            return
        for robot in robots:
            for scope in robot.instances:
                yield from self._scope_events(robot, scope)
            if robot.instances:
                continue
            for start in robot.plan.triggered_starts:
                if self._may_fire(robot, start):
                    yield (
                        f"{robot.name}: {start.label}",
                        methodcaller("start_instance", robot, start, ""),
                    )

    def _scope_events(self, robot: Robot, scope: Scope) -> Iterator[tuple[str, Action]]:
        if scope.plan is not None:
            for esp in scope.plan.event_subprocesses:
                starts = esp.content.triggered_starts
                start = starts[0] if starts else None
                if start is None or not self._may_fire(robot, start):
                    continue
                if self.registry.node_id(esp) in scope.fired or any(
                    t.node is esp for t in scope.tokens
                ):
                    continue  # a handler the world starts runs once at a time
                yield (
                    f"{robot.name}: {start.label}",
                    methodcaller("fire_esp", scope, esp, ""),
                )
        for token in scope.tokens:
            yield from self._token_events(robot, token)
            if token.child is not None:
                yield from self._scope_events(robot, token.child)

    def _token_events(self, robot: Robot, token: Tok) -> Iterator[tuple[str, Action]]:
        node = token.node
        if token.waiting == "wait":
            if node.behaviour == Run.CATCH and self._may_fire(robot, node, token):
                yield (
                    f"{robot.name}: {node.label}",
                    _fire_where_it_is(token),
                )
            elif node.behaviour in (Run.SKILL, Run.SCRIPT):
                yield (f"{robot.name}: {node.label} ends", methodcaller("finished", token))
            elif node.behaviour == Run.EVENT_BASED_GATEWAY:
                for flow in node.outgoing:
                    if self._may_fire(robot, flow.target, token):
                        yield (
                            f"{robot.name}: {flow.target.label}",
                            methodcaller("fire", token, flow.target, ""),
                        )
        if token.waiting == "wait" or token.child is not None:
            for boundary in node.boundaries:
                if not self._may_fire(robot, boundary, token):
                    continue
                if not boundary.node.cancel_activity and any(
                    t.node is boundary or t.flow in _out(boundary) for t in token.scope.tokens
                ):
                    continue  # a non-interrupting event of the world: once at a time
                yield (
                    f"{robot.name}: {boundary.label}",
                    methodcaller("fire_boundary", token, boundary, ""),
                )

    def _may_fire(self, robot: Robot, catcher: NodePlan, token: Tok | None = None) -> bool:
        """Whether ``catcher`` may fire on its own: a timer no earlier deadline comes before,
        a conditional event whose condition may hold, a signal or error the world throws."""
        trigger = catcher.trigger
        if trigger is None:
            return False
        if trigger.kind == EventKind.TIMER:
            return token is None or self._first_due(token, catcher)
        if trigger.kind == EventKind.CONDITIONAL:
            return condition_holds(event_condition(catcher), robot) is not False
        if trigger.kind == EventKind.ERROR:  # a battery monitor, a skill: errors the world raises
            return f"/{trigger.topic}" in self.outside
        return trigger.kind == EventKind.SIGNAL and trigger.topic in self.outside

    def _first_due(self, token: Tok, catcher: NodePlan) -> bool:
        """A timer armed at or before this one with a shorter duration is due first: the
        others' durations, not the skills' unknown ones, order timers."""
        duration = timer_seconds(catcher)
        if duration is None:
            return True
        return not any(
            other is not None and since <= token.since and other < duration
            for since, other, holder, timer in self._armed_timers
            if not (holder is token and timer is catcher)
        )


def condition_holds(expression: Expression | None, robot: Robot) -> Any:
    """True, False or UNKNOWN: ``expression`` over ``robot``'s tracked variables."""
    if expression is None:
        return True
    tree = condition_tree(expression.text, expression.language)
    values = {name: value for name, (value, _) in robot.variables.items()}
    return truth(evaluate(tree, values))


def event_condition(node: NodePlan) -> Expression | None:
    event = node.node.event
    return event.condition if event is not None else None


def _out(node: NodePlan) -> set[str]:
    return {f.id for f in node.outgoing}
