"""One step: an event and everything it sets off without waiting, in every robot, as the
engines run it (the behaviour of each element, signals broadcast, errors caught, data
followed), with the choices it is given.
"""

from __future__ import annotations

import ast
import functools
from collections import deque
from collections.abc import Callable, Iterator
from itertools import combinations
from typing import Any

from robotale.fame_runtime.expressions import self_reference
from robotale.fame_runtime.kinds import EventKind, LoopKind, Run
from robotale.fame_runtime.model import Expression
from robotale.fame_runtime.plan import FlowPlan, NodePlan, ScopePlan, reachable_flows
from robotale.fame_runtime.tags import Lifecycle, Tag
from robotale.fame_runtime.verify.registry import ElementKey, element_key
from robotale.fame_runtime.verify.space import (
    ASSUMED,
    BUSY_TAGS,
    INSTANCE_CAP,
    NOW,
    STEP_CAP,
    TOKEN_CAP,
    Space,
    condition_holds,
    event_condition,
)
from robotale.fame_runtime.verify.state import (
    Choices,
    Decision,
    Outcome,
    Robot,
    Scope,
    State,
    Tok,
    scopes,
)
from robotale.fame_runtime.verify.values import (
    UNKNOWN,
    condition_names,
    condition_tree,
    evaluate,
    parameter_value,
    script_effect,
)

# -- one step ------------------------------------------------------------------------------------


class Step:
    """Runs one event and everything it sets off, with the choices given."""

    def __init__(self, space: Space, state: State, choices: Choices, stamp: float) -> None:
        self.space = space
        self.robots = space.thaw(state)
        self.choices = choices
        self.stamp = stamp
        self.work: deque[Callable[[], None]] = deque()
        self.tags: list[Tag] = []
        self.reached: set[ElementKey] = set()
        self.armed: set[ElementKey] = set()
        self.fired: set[ElementKey] = set()
        self.decisions: list[Decision] = []
        self.lost: list[tuple[str, NodePlan, str]] = []
        self.failures: list[tuple[str, str, NodePlan, str]] = []
        self.messages = 0
        self.capped = False  # a catcher was left out by TOKEN_CAP
        self.current: Tok | None = None  # the token that moved last
        #: (token, node) entered in this step, (token, "round") for a loop's rounds
        self.entered: set[tuple[int, object]] = set()
        self.urgent = False  # the step only went on with a loop's next round
        self.set_now: set[tuple[str, str]] = set()  # (robot, variable) set in this step

    def run(self, event: Callable[[Step], None]) -> Outcome:
        event(self)
        steps = 0
        while self.work:
            steps += 1
            if steps > STEP_CAP:
                self._busy()
                continue
            self.work.popleft()()
            if not self.work and self.space.inclusive:
                self._inclusive_joins()
        for robot in self.robots:
            for name in robot.later:  # a callback may have written it while the robot waits
                robot.variables.pop(name, None)
        return Outcome(
            self.space.freeze(self.robots),
            self.tags,
            self.reached,
            self.armed,
            self.fired,
            self.decisions,
            self.lost,
            self.capped,
            self.failures,
            self.urgent,
        )

    def tag(
        self, robot: Robot, label: str, lifecycle: Lifecycle, msg_id: str = "", role: str = ""
    ) -> None:
        self.tags.append(Tag(self.stamp, robot.name, label, lifecycle.value, msg_id, role))

    def pair(self, robot: Robot, label: str, msg_id: str = "", role: str = "") -> None:
        self.tag(robot, label, Lifecycle.START, msg_id, role)
        self.tag(robot, label, Lifecycle.COMPLETE, msg_id, role)

    # -- events ----------------------------------------------------------------------------------

    def begin(self, robot: Robot) -> None:
        robot.begun = True
        self.declare(robot, robot.plan, first=True)
        if not robot.plan.starts:
            return
        scope = Scope(robot, robot.plan, None)
        robot.instances.append(scope)
        for start in robot.plan.starts:
            self._go(Tok(scope, start), start)

    def start_instance(self, robot: Robot, start: NodePlan, msg_id: str) -> None:
        scope = Scope(robot, robot.plan, None)
        robot.instances.append(scope)
        self.declare(robot, robot.plan)
        token = Tok(scope, start)
        scope.tokens.append(token)
        self._caught(token, start, msg_id)

    def fire(self, token: Tok, catcher: NodePlan, msg_id: str) -> None:
        """A waiting catch event (or an event-based gateway's ``catcher``) fires."""
        if not token.alive:
            return
        token.waiting = ""
        self._caught(token, catcher, msg_id)

    def fire_boundary(self, token: Tok, boundary: NodePlan, msg_id: str) -> None:
        if not token.alive:
            return
        scope = token.scope
        if boundary.node.cancel_activity:
            self._cancel(token)
        new = Tok(scope, boundary)
        scope.tokens.append(new)
        self._caught(new, boundary, msg_id)

    def fire_esp(self, scope: Scope, esp: NodePlan, msg_id: str) -> None:
        if scope.closed:
            return
        start = esp.content.triggered_starts[0]
        interrupting = start.node.interrupting or start.caught.kind == EventKind.ERROR
        if interrupting:
            scope.fired.add(self.space.registry.node_id(esp))
            for token in list(scope.tokens):
                self._cancel(token)
        holder = Tok(scope, esp, waiting="wait")
        scope.tokens.append(holder)
        # as the engine tags it: the trigger is caught first, then the sub-process starts
        self._catch(scope.robot, start, msg_id)
        self.reached.add(element_key(esp))
        self.tag(scope.robot, esp.label, Lifecycle.START)
        child = Scope(scope.robot, esp.child, holder)
        holder.child = child
        self.declare(scope.robot, esp.child)
        token = Tok(child, start)
        child.tokens.append(token)
        self.data_out(scope.robot, start)
        self._leave(token, start)

    def resume(self, token: Tok) -> None:
        """A token paused at the next round of a loop goes on."""
        self.urgent = True
        if token.waiting == "again":  # a loop activity's next round
            token.waiting = "wait"
            self.entered.add((id(token), "round"))
            self._loop_body(token, token.node)
            return
        token.waiting = ""
        self.work.append(lambda: self._enter(token, token.node))

    def finished(self, token: Tok) -> None:
        """A skill, or a script completing from a callback, ends."""
        if not token.alive:
            return
        token.waiting = ""
        if token.node.behaviour == Run.SKILL:
            self.forget_assumptions(token.scope.robot)
        self.tag(token.scope.robot, token.node.label, Lifecycle.COMPLETE)
        self.data_out(token.scope.robot, token.node)
        self._leave(token, token.node)

    # -- moving tokens ---------------------------------------------------------------------------

    def _go(self, token: Tok, node: NodePlan) -> None:
        if token not in token.scope.tokens:
            token.scope.tokens.append(token)
        self.work.append(lambda: self._enter(token, node))

    def _caught(self, token: Tok, catcher: NodePlan, msg_id: str) -> None:
        robot = token.scope.robot
        token.node = catcher
        self._catch(robot, catcher, msg_id)
        self.data_out(robot, catcher)
        self._leave(token, catcher)

    def _catch(self, robot: Robot, catcher: NodePlan, msg_id: str) -> None:
        """``catcher`` fires for ``robot``: tagged, its message in the variables."""
        if msg_id:
            self.forget_assumptions(robot)
        self.reached.add(element_key(catcher))
        self.fired.add(element_key(catcher))
        self.pair(robot, catcher.label, msg_id, "receive" if msg_id else "")
        if msg_id:  # the message becomes the variable named after its signal
            topic = catcher.trigger.topic if catcher.trigger is not None else ""
            robot.variables.pop(topic.strip("/").replace("/", "_"), None)

    def _busy(self) -> None:
        """The step never waits: the engine stops the robot whose token keeps going with a
        model error; so does the step here."""
        token = self.current
        assert token is not None  # a step that runs has moved a token
        self.work.clear()
        del self.tags[BUSY_TAGS:]  # the trace shows the loop's first rounds, not all of them
        self.failures.append(
            (
                "stuck",
                token.scope.robot.name,
                token.node,
                f"{token.node.node.kind} {token.node.node.describe()} is in a loop that never "
                "waits: the engine stops the robot with a model error",
            )
        )
        self._kill_instance(token)

    def _enter(self, token: Tok, node: NodePlan) -> None:
        if not token.alive:
            return
        if (id(token), id(node)) in self.entered:
            # round a loop without waiting: the next round is a step of its own (urgent:
            # nothing else happens before it), so the state graph has the loop, not the step
            token.node, token.waiting = node, "ready"
            return
        self.entered.add((id(token), id(node)))
        self.current = token
        token.node = node
        self.reached.add(element_key(node))
        _BEHAVIOURS.get(node.behaviour, Step._run_pass)(self, token, node)

    def _leave(self, token: Tok, node: NodePlan) -> None:
        self._follow(token, self._taken(token, node, first=False))

    def _follow(self, token: Tok, flows: list[FlowPlan]) -> None:
        if not flows:
            self._consume(token)
            return
        for flow in flows[1:]:
            other = Tok(token.scope, flow.target, flow.id)
            self._go(other, flow.target)
        token.flow = flows[0].id
        self._go(token, flows[0].target)

    def _taken(self, token: Tok, node: NodePlan, *, first: bool) -> list[FlowPlan]:
        """The flows to take, a choice among the possible ones when a condition is unknown."""
        robot = token.scope.robot
        conditional = [f for f in node.outgoing if f is not node.default]
        if all(f.condition is None for f in conditional):
            taken = conditional[:1] if first else conditional
            return taken or ([node.default] if node.default is not None else [])
        values = [condition_holds(self.space.registry.condition(f), robot) for f in conditional]
        options = _first_options(values) if first else _all_options(values)
        options = [o or ([node.default] if node.default is not None else []) for o in options]
        options = [[conditional[i] if isinstance(i, int) else i for i in o] for o in options]
        pick = self.choices.pick(len(options))
        chosen = options[pick]
        self._assume(robot, node, conditional, values, chosen, first=first)
        self.decisions.append(
            Decision(
                robot.name,
                node,
                tuple(f.id for f in chosen),
                _reads(
                    [self.space.registry.condition(f) for f in conditional], robot, self.set_now
                ),
            )
        )
        return chosen

    def _assume(
        self,
        robot: Robot,
        node: NodePlan,
        flows: list[FlowPlan],
        values: list[Any],
        chosen: list[FlowPlan],
        *,
        first: bool,
    ) -> None:
        """An unknown variable a condition tested keeps the value the choice implies until
        something writes it (``a`` taken: a is true), so a later test of it agrees."""
        taken = {id(f) for f in chosen}
        for flow, value in zip(flows, values, strict=True):
            if value is not UNKNOWN:
                continue
            if id(flow) in taken:
                outcome = True
            elif not first or (chosen and flows.index(chosen[0]) > flows.index(flow)):
                outcome = False
            else:
                continue
            expression = self.space.registry.condition(flow)
            if expression is None:  # no condition: it holds, never unknown
                continue
            implied = _implied(condition_tree(expression.text, expression.language), outcome)
            if implied is not None and implied[0] not in robot.later:
                robot.variables[implied[0]] = (implied[1], ASSUMED + node.node.describe())

    def _set(self, robot: Robot, values: dict[str, Any], setter: str) -> None:
        for name, value in values.items():
            if name not in self.space.relevant:
                continue
            if value is UNKNOWN:
                robot.variables.pop(name, None)
            else:
                robot.variables[name] = (value, setter)
                self.set_now.add((robot.name, name))

    def _known(self, robot: Robot) -> dict[str, Any]:
        return {name: value for name, (value, _) in robot.variables.items()}

    def data_in(self, robot: Robot, node: NodePlan) -> None:
        """Before an activity: its data inputs and input parameters become variables."""
        known = self._known(robot)
        values = {
            name: parameter_value(text, known)
            for data_object in node.data_inputs
            for name, text in data_object.parameters.items()
        }
        values |= {n: parameter_value(v, known) for n, v in node.node.inputs.items()}
        self._set(robot, values, node.node.describe())

    def data_out(self, robot: Robot, node: NodePlan) -> None:
        """After an activity or a catch: output parameters and data outputs (what reads the
        activity's outputs or the message's fields, which are not tracked, is unknown)."""
        known = self._known(robot)
        values = {n: parameter_value(v, known) for n, v in node.node.outputs.items() if v}
        values |= {
            name: parameter_value(text, known)
            for data_object in node.data_outputs
            for name, text in data_object.parameters.items()
        }
        self._set(robot, values, node.node.describe())

    def declare(self, robot: Robot, plan: ScopePlan | None, *, first: bool = False) -> None:
        """A scope opens: its data objects' literal values become variables; ``${name}``
        declares ``name`` (None when the robot's first instance begins, when nothing can have
        set it yet)."""
        if plan is None:
            return
        literal = {
            name: parameter_value(text, {})
            for data_object in plan.data_objects
            for name, text in data_object.parameters.items()
            if "${" not in text
        }
        if first:
            declared = {
                name: None
                for data_object in plan.data_objects
                for name, text in data_object.parameters.items()
                if self_reference(text) == name and name not in robot.variables
            }
            literal = declared | literal
        self._set(robot, literal, f"a data object of {plan.process.describe()}")

    def forget_assumptions(self, robot: Robot) -> None:
        """A skill's outputs or a message's data may have written any variable."""
        for name, (_, setter) in list(robot.variables.items()):
            if setter.startswith(ASSUMED):
                del robot.variables[name]

    def _consume(self, token: Tok) -> None:
        token.alive = False
        scope = token.scope
        if token in scope.tokens:
            scope.tokens.remove(token)
        if not scope.tokens and not scope.closed:
            self._close(scope)

    def _cancel(self, token: Tok) -> None:
        token.alive = False
        if token in token.scope.tokens:
            token.scope.tokens.remove(token)
        if token.child is not None:
            self._cancel_scope(token.child)
            token.child = None

    def _cancel_scope(self, scope: Scope) -> None:
        scope.closed = True
        for token in list(scope.tokens):
            self._cancel(token)

    def _close(self, scope: Scope) -> None:
        """``scope`` has no token left: its holder goes on (a top scope: the instance ends)."""
        self._cancel_scope(scope)
        holder = scope.holder
        robot = scope.robot
        if holder is None:
            if scope in robot.instances:
                robot.instances.remove(scope)
            return
        if not holder.alive:
            return
        holder.child = None
        holder.waiting = ""
        node = holder.node
        if node.behaviour == Run.LOOP:
            self._loop_round(holder, node)
            return
        self.tag(robot, node.label, Lifecycle.COMPLETE)
        if node.behaviour == Run.EVENT_SUBPROCESS:
            self._consume(holder)
            return
        self.data_out(robot, node)
        self._leave(holder, node)

    def _kill(self, scope: Scope) -> None:
        for token in list(scope.tokens):
            self._cancel(token)
        if not scope.closed:
            self._close(scope)

    # -- behaviours ------------------------------------------------------------------------------

    def _run_pass(self, token: Tok, node: NodePlan) -> None:
        throw = node.throw
        if throw is not None and throw.kind in (EventKind.SIGNAL, EventKind.MESSAGE):
            self._publish(token.scope.robot, node)
        elif throw is not None:
            self.pair(token.scope.robot, throw.label)
        self._leave(token, node)

    def _run_end(self, token: Tok, node: NodePlan) -> None:
        throw = node.throw
        robot = token.scope.robot
        if throw is not None and throw.kind in (EventKind.SIGNAL, EventKind.MESSAGE):
            self._publish(robot, node)
        elif throw is not None and throw.kind == EventKind.ERROR:
            self.pair(robot, throw.label)
            self._throw_error(token, throw.topic)
            return
        elif throw is not None:
            self.pair(robot, throw.label)
        self._consume(token)

    def _run_terminate(self, token: Tok, node: NodePlan) -> None:
        self._kill(token.scope)

    def _run_task(self, token: Tok, node: NodePlan) -> None:
        robot = token.scope.robot
        self.tag(robot, node.label, Lifecycle.START)
        self.data_in(robot, node)
        self.tag(robot, node.label, Lifecycle.COMPLETE)
        self.data_out(robot, node)
        self._leave(token, node)

    def _run_script(self, token: Tok, node: NodePlan) -> None:
        robot = token.scope.robot
        self.tag(robot, node.label, Lifecycle.START)
        self.data_in(robot, node)
        script = node.node.script
        effect = script_effect(script.text, script.language) if script is not None else None
        if effect is not None:
            values = {name: value for name, (value, _) in robot.variables.items()}
            for name, tree in effect.sets:
                value = evaluate(tree, values)
                values[name] = value
                if value is UNKNOWN:
                    robot.variables.pop(name, None)
                else:
                    if name in self.space.relevant:
                        robot.variables[name] = (value, node.node.describe())
                    self.set_now.add((robot.name, name))
            for name in effect.havoc:
                robot.variables.pop(name, None)
            if effect.unreadable:
                robot.variables.clear()
            robot.later |= effect.later & self.space.relevant
            if effect.waits:
                token.waiting = "wait"
                self._armed(token)
                return
        self.tag(robot, node.label, Lifecycle.COMPLETE)
        self.data_out(robot, node)
        self._leave(token, node)

    def _run_skill(self, token: Tok, node: NodePlan) -> None:
        self.tag(token.scope.robot, node.label, Lifecycle.START)
        self.data_in(token.scope.robot, node)
        token.waiting = "wait"
        self._armed(token)

    def _run_call(self, token: Tok, node: NodePlan) -> None:
        robot = token.scope.robot
        self.tag(robot, node.label, Lifecycle.START)
        self.data_in(robot, node)
        token.waiting = "wait"
        self._armed(token)
        child = Scope(robot, node.child, token)
        token.child = child
        self.declare(robot, node.child)
        if not node.content.starts:
            self._close(child)
            return
        for start in node.content.starts:
            self._go(Tok(child, start), start)

    def _run_loop(self, token: Tok, node: NodePlan) -> None:
        token.waiting = "wait"
        self._armed(token)
        marker = node.looping.loop
        # tested before: maybe no round at all
        if marker.kind == LoopKind.STANDARD and marker.test_before and not self._again(token, node):
            self._loop_done(token, node)
            return
        self._loop_body(token, node)

    def _loop_body(self, token: Tok, node: NodePlan) -> None:
        child = Scope(token.scope.robot, None, token)
        token.child = child
        body = node.looping.body
        self._go(Tok(child, body), body)

    def _loop_round(self, token: Tok, node: NodePlan) -> None:
        """A round of a loop ended: a standard loop goes round again while its condition may
        hold (a multi-instance activity's instances are alike: one round stands for all)."""
        again = node.looping.loop.kind == LoopKind.STANDARD and self._again(token, node)
        if again and (id(token), "round") in self.entered:
            token.waiting = "again"  # the next round is a step of its own, as in _enter
            return
        if again:
            self.entered.add((id(token), "round"))
            token.waiting = "wait"
            self._loop_body(token, node)
            return
        self._loop_done(token, node)

    def _again(self, token: Tok, node: NodePlan) -> bool:
        """Whether a standard loop goes round (again): its condition, a choice when unknown
        or when a loopMaximum may end it (rounds are not counted)."""
        marker = node.looping.loop
        holds = condition_holds(marker.condition, token.scope.robot)
        if marker.condition is None or (holds is True and marker.maximum is not None):
            holds = UNKNOWN
        return bool(holds) if holds is not UNKNOWN else self.choices.pick(2) == 1

    def _loop_done(self, token: Tok, node: NodePlan) -> None:
        token.waiting = ""
        token.child = None
        self.tag(token.scope.robot, node.label, Lifecycle.COMPLETE)
        self._leave(token, node)

    def _run_catch(self, token: Tok, node: NodePlan) -> None:
        trigger = node.trigger
        conditional = trigger is not None and trigger.kind == EventKind.CONDITIONAL
        if conditional and condition_holds(event_condition(node), token.scope.robot) is True:
            self._caught(token, node, "")
            return
        token.waiting = "wait"
        self._armed(token)

    def _run_event_gateway(self, token: Tok, node: NodePlan) -> None:
        token.waiting = "wait"
        token.since = NOW
        for flow in node.outgoing:
            self.armed.add(element_key(flow.target))

    def _run_exclusive(self, token: Tok, node: NodePlan) -> None:
        self._split(token, node, first=True)

    def _run_inclusive(self, token: Tok, node: NodePlan) -> None:
        if len(node.incoming) > 1:
            token.waiting = "join"
            return
        self._split(token, node, first=False)

    def _split(self, token: Tok, node: NodePlan, *, first: bool) -> None:
        """An exclusive (``first``) or inclusive split; no flow to take stops the robot."""
        flows = self._taken(token, node, first=first)
        if not flows:
            self._stuck(token, node)
            return
        self._follow(token, flows)

    def _run_parallel(self, token: Tok, node: NodePlan) -> None:
        if len(node.incoming) <= 1:
            self._follow(token, list(node.outgoing))
            return
        token.waiting = "join"
        waiting = [t for t in token.scope.tokens if t.node is node and t.waiting == "join"]
        arrived = {t.flow for t in waiting}
        if not arrived.issuperset(node.incoming):
            return
        for flow_id in node.incoming:
            first = next(t for t in waiting if t.flow == flow_id)
            if first is not token:
                first.alive = False
                token.scope.tokens.remove(first)
        token.waiting = ""
        self._follow(token, list(node.outgoing))

    def _inclusive_joins(self) -> None:
        for robot in self.robots:
            for scope in scopes(robot):
                for node in {
                    id(t.node): t.node for t in scope.tokens if t.waiting == "join"
                }.values():
                    if node.behaviour == Run.INCLUSIVE_GATEWAY and _may_merge(scope, node):
                        self._merge(scope, node)

    def _merge(self, scope: Scope, node: NodePlan) -> None:
        survivor, *others = [t for t in scope.tokens if t.node is node and t.waiting == "join"]
        for other in others:
            other.alive = False
            scope.tokens.remove(other)
        survivor.waiting = ""
        self._split(survivor, node, first=False)

    def _stuck(self, token: Tok, node: NodePlan) -> None:
        robot = token.scope.robot
        self.failures.append(
            (
                "stuck",
                robot.name,
                node,
                f"{node.node.kind} {node.node.describe()} has no outgoing flow whose condition "
                "holds and no default flow: the engine stops the robot with a model error",
            )
        )
        self._kill_instance(token)

    # -- signals and errors ----------------------------------------------------------------------

    def _publish(self, robot: Robot, node: NodePlan) -> None:
        throw = node.thrown
        self.messages += 1
        msg_id = f"m{int(self.stamp)}.{self.messages}"  # unique in a trace: one step a stamp
        self.tag(robot, throw.label, Lifecycle.START, msg_id, "send")
        receivers = list(self._receivers(throw.topic))
        if not receivers and not self.capped:
            self.lost.append((robot.name, node, throw.topic))
        for receive in receivers:
            self.work.append(functools.partial(receive, msg_id))
        self.tag(robot, throw.label, Lifecycle.COMPLETE, msg_id, "send")

    def _receivers(self, topic: str) -> Iterator[Callable[[str], None]]:
        """Everything armed for ``topic`` now, in every robot (a broadcast)."""
        for robot in self.robots:
            for scope in scopes(robot):
                yield from self._scope_receivers(scope, topic)
            for start in robot.plan.triggered_starts:
                if not _listens(start, topic):
                    continue
                if len(robot.instances) >= INSTANCE_CAP:
                    self.capped = True  # not lost: more instances than the bound keeps
                    continue
                yield functools.partial(self.start_instance, robot, start)

    def _scope_receivers(self, scope: Scope, topic: str) -> Iterator[Callable[[str], None]]:
        if scope.plan is not None:
            for esp in scope.plan.event_subprocesses:
                starts = esp.content.triggered_starts
                fired = self.space.registry.node_id(esp) in scope.fired
                if not starts or not _listens(starts[0], topic) or fired:
                    continue
                if len(scope.tokens) >= TOKEN_CAP:
                    self.capped = True
                    continue
                yield functools.partial(self.fire_esp, scope, esp)
        for token in list(scope.tokens):
            node = token.node
            if token.waiting == "wait" and node.behaviour == Run.CATCH and _listens(node, topic):
                yield _fire_where_it_is(self, token)
            if token.waiting == "wait" and node.behaviour == Run.EVENT_BASED_GATEWAY:
                for flow in node.outgoing:
                    if _listens(flow.target, topic):
                        yield functools.partial(self.fire, token, flow.target)
            if token.waiting == "wait" or token.child is not None:
                for boundary in node.boundaries:
                    if _listens(boundary, topic):
                        yield functools.partial(self.fire_boundary, token, boundary)

    def _throw_error(self, token: Tok, name: str) -> None:
        """To the nearest catcher: event sub-processes of each scope and boundary events of
        the activity holding it, innermost first; nobody: the instance fails."""
        scope: Scope | None = token.scope
        self._consume_quietly(token)
        while scope is not None:
            if scope.plan is not None:
                for esp in scope.plan.event_subprocesses:
                    starts = esp.content.triggered_starts
                    if starts and _catches_error(starts[0], name):
                        self.fire_esp(scope, esp, "")
                        return
            holder = scope.holder
            if holder is None:
                break
            for boundary in holder.node.boundaries:
                if _catches_error(boundary, name):
                    self.fire_boundary(holder, boundary, "")
                    return
            scope = holder.scope
        robot = token.scope.robot
        self.failures.append(
            (
                "uncaught",
                robot.name,
                token.node,
                f"error {name!r} thrown at {token.node.node.describe()} is caught by nobody: "
                "the robot's instance ends",
            )
        )
        self._kill_instance(token)

    def _consume_quietly(self, token: Tok) -> None:
        token.alive = False
        if token in token.scope.tokens:
            token.scope.tokens.remove(token)

    def _kill_instance(self, token: Tok) -> None:
        scope = token.scope
        while scope.holder is not None:
            scope = scope.holder.scope
        self._cancel_scope(scope)
        if scope in scope.robot.instances:
            scope.robot.instances.remove(scope)

    def _armed(self, token: Tok) -> None:
        """Note the catchers ``token`` arms (for catches that never fire); its timers start
        now, after every timer of the state."""
        token.since = NOW
        node = token.node
        if node.trigger is not None:
            self.armed.add(element_key(node))
        for boundary in node.boundaries:
            self.armed.add(element_key(boundary))


def _implied(tree: ast.expr | None, outcome: bool) -> tuple[str, Any] | None:
    """The variable value a test's outcome implies: ``a`` / ``not a`` / ``a == 3``."""
    if isinstance(tree, ast.Name):
        return (tree.id, outcome)
    if isinstance(tree, ast.UnaryOp) and isinstance(tree.op, ast.Not):
        inner = _implied(tree.operand, not outcome)
        return inner
    if (
        outcome
        and isinstance(tree, ast.Compare)
        and isinstance(tree.left, ast.Name)
        and len(tree.ops) == 1
        and isinstance(tree.ops[0], ast.Eq)
        and isinstance(tree.comparators[0], ast.Constant)
    ):
        return (tree.left.id, tree.comparators[0].value)
    return None


def _listens(node: NodePlan, topic: str) -> bool:
    trigger = node.trigger
    return trigger is not None and trigger.kind == EventKind.SIGNAL and trigger.topic == topic


def _catches_error(node: NodePlan, name: str) -> bool:
    trigger = node.trigger
    return trigger is not None and trigger.kind == EventKind.ERROR and trigger.topic in ("", name)


def _may_merge(scope: Scope, node: NodePlan) -> bool:
    """An inclusive join goes on when no other token of its scope can still reach an incoming
    flow that has no token yet (as the engine decides)."""
    waiting = [t for t in scope.tokens if t.node is node and t.waiting == "join"]
    missing = set(node.incoming) - {t.flow for t in waiting}
    return not any(
        missing & reachable_flows(t.node)
        for t in scope.tokens
        if not (t.node is node and t.waiting == "join")
    )


def _first_options(values: list[Any]) -> list[list[Any]]:
    """An exclusive split: the first flow whose condition holds; an unknown one may or may
    not (the index list of each possible outcome). With an unknown condition one of the flows
    is taken (the modeller's conditions are taken to cover every case): [] = none holds is an
    outcome only when the tracked values decide every condition."""
    options: list[list[Any]] = []
    for index, value in enumerate(values):
        if value is True:
            options.append([index])
            return options
        if value is UNKNOWN:
            options.append([index])
    return options or [[]]


def _all_options(values: list[Any]) -> list[list[Any]]:
    """An inclusive split (or a node's conditional flows): every flow whose condition holds,
    and each combination of the unknown ones that takes at least one."""
    sure = [i for i, v in enumerate(values) if v is True]
    unsure = [i for i, v in enumerate(values) if v is UNKNOWN]
    options = [
        sorted(sure + list(extra))
        for size in range(len(unsure) + 1)
        for extra in combinations(unsure, size)
    ]
    return [o for o in options if o] or [[]]


def _reads(
    conditions: list[Expression | None], robot: Robot, set_now: set[tuple[str, str]]
) -> tuple[tuple[str, Any, str, bool], ...]:
    """The tracked variables the conditions read: value and who set it."""
    reads = []
    for condition in conditions:
        if condition is None:
            continue
        for name in condition_names(condition.text, condition.language):
            value, setter = robot.variables.get(name, (UNKNOWN, ""))
            reads.append((name, value, setter, (robot.name, name) in set_now))
    return tuple(dict.fromkeys(reads))


def _fire_where_it_is(step: Step, token: Tok) -> Callable[[str], None]:
    """Fire ``token``'s catching event where the token is when the message arrives."""
    return lambda msg_id: step.fire(token, token.node, msg_id)


_BEHAVIOURS: dict[str, Callable[[Step, Tok, NodePlan], None]] = {
    Run.START: Step._leave,
    Run.BOUNDARY: Step._leave,
    Run.PASS: Step._run_pass,
    Run.END: Step._run_end,
    Run.TERMINATE: Step._run_terminate,
    Run.TASK: Step._run_task,
    Run.SCRIPT: Step._run_script,
    Run.SKILL: Step._run_skill,
    Run.CALL: Step._run_call,
    Run.SUBPROCESS: Step._run_call,
    Run.LOOP: Step._run_loop,
    Run.CATCH: Step._run_catch,
    Run.EXCLUSIVE_GATEWAY: Step._run_exclusive,
    Run.INCLUSIVE_GATEWAY: Step._run_inclusive,
    Run.PARALLEL_GATEWAY: Step._run_parallel,
    Run.EVENT_BASED_GATEWAY: Step._run_event_gateway,
    Run.EVENT_SUBPROCESS: lambda step, token, node: None,
}
