"""The token engine: one per robot, running that robot's process (BPMN 2.0 section 13).

Tokens move through the process as far as they can without waiting; a token waits at a skill
that takes time, a catching event, a sub-process, a join. Everything that wakes a token up --
a message on the bus, a timer, a skill's ``done``, a variable change satisfying a condition --
is queued and run by the engine's own loop, never inside another engine's step or inside the
bus. Every activity start and completion, every signal thrown or caught, every timer, error
and conditional event becomes a :class:`~robotale.fame_runtime.tags.Tag`; an activity that is
interrupted or cancelled ends with an ``ate_abort`` tag instead of ``complete``.

The engine keeps the tokens and scopes (:mod:`robotale.fame_runtime.tokens`) and moves them;
how each kind of element runs is its behaviour (:mod:`robotale.fame_runtime.behaviours`).
See ``docs/fame_runtime.md`` for the API and the exact semantics.
"""

from __future__ import annotations

import builtins
import contextlib
from collections import deque
from collections.abc import Callable, Iterable, Mapping
from pathlib import Path
from typing import Any, ClassVar

from robotale.errors import ModelError
from robotale.fame_runtime import watchdog
from robotale.fame_runtime.behaviours import BEHAVIOURS, Behaviour
from robotale.fame_runtime.behaviours.activities import activity_done
from robotale.fame_runtime.behaviours.boundaries import arm_event_subprocess, event_subprocess
from robotale.fame_runtime.behaviours.catching import caught
from robotale.fame_runtime.behaviours.gateways import recheck_joins
from robotale.fame_runtime.behaviours.loops import instance_done
from robotale.fame_runtime.bus import Bus, Envelope
from robotale.fame_runtime.clock import Clock, EngineTime
from robotale.fame_runtime.conditions import Conditions
from robotale.fame_runtime.data import Data
from robotale.fame_runtime.expressions import BpmnError
from robotale.fame_runtime.javascript import JavaScript
from robotale.fame_runtime.library import Library
from robotale.fame_runtime.model import Process
from robotale.fame_runtime.plan import FlowPlan, NodePlan, ScopePlan, deploy, speaks_javascript
from robotale.fame_runtime.robot import RobotHandle
from robotale.fame_runtime.running import ActivityObserver, RunningActivities
from robotale.fame_runtime.skills import Skill
from robotale.fame_runtime.tags import Lifecycle, Tagger, TagSink
from robotale.fame_runtime.tokens import Frame, RunScope, Token, install
from robotale.fame_runtime.triggers import Triggers

#: steps one engine may take without its clock moving on: more means a loop with no wait
MAX_STEPS = 1_000_000

#: what charging work costs when the engine's clock charges nothing
_FREE = contextlib.nullcontext()


class Engine:
    """Runs one robot's process.

    ``process`` is a parsed :class:`~robotale.fame_runtime.model.Process` (or an already
    deployed plan); ``skills`` maps called-element names to Python skills; ``library`` is a
    folder of .bpmn building blocks for call activities; ``variables`` are initial variables
    (they win over the data objects' literal values); ``tag_sink`` receives every tag;
    ``output`` prints what JavaScript scripts ``console.log`` (default: standard output, each
    line prefixed with the robot's name).
    """

    #: how a node runs, by the behaviour the deployer gave it (``NodePlan.behaviour``)
    _BEHAVIOURS: ClassVar[dict[str, Behaviour]] = BEHAVIOURS

    def __init__(
        self,
        process: Process | ScopePlan,
        *,
        robot: str,
        bus: Bus,
        clock: Clock,
        robot_type: str = "",
        skills: Mapping[str, Skill] | None = None,
        tag_sink: TagSink | None = None,
        library: Library | str | Path | None = None,
        variables: Mapping[str, Any] | None = None,
        output: Callable[[str], None] | None = None,
    ) -> None:
        self.skills = dict(skills or {})
        if library is not None and not isinstance(library, Library):
            library = Library(library)
        self.library = library
        self.plan = self._deploy(process)
        self.bus, self.clock = bus, clock
        self.variables: dict[str, Any] = dict(variables or {})
        robot_type = robot_type or self.plan.process.name or self.plan.process.id
        self.robot = RobotHandle(robot, robot_type, bus, clock, self.variables, self.changed)
        self.env: dict[str, Any] = {
            "__builtins__": builtins,
            "robot": self.robot,
            "BpmnError": BpmnError,
        }
        self.data = Data(robot, self.variables, self.env, self.changed)
        self.data.keep_unset = speaks_javascript(self.plan)
        self.tag = Tagger(robot, clock, tag_sink, bus)
        self.conditions = Conditions(
            robot,
            self.env,
            self.variables,
            javascript=lambda: self.javascript,
            charged=self.charged,
        )
        self.triggers = Triggers(
            robot, bus, clock, self.call, self.conditions.event, self.env, self.variables
        )
        self._work: deque[Callable[[], object]] = deque()  # first queued, first run
        self._busy = False
        self._steps = 0
        self._roots: list[RunScope] = []
        self._start_disarms: list[Callable[[], object]] = []
        self.inclusive: set[RunScope] = set()  # scopes with a token waiting at inclusive joins
        self._when_idle: list[Callable[[], object]] = []
        self._starting = 0  # none-start instances scheduled but not begun
        self.started = False
        self.stopped = False
        self.completed = 0  # process instances that ended normally
        self.failed = 0  # process instances an uncaught error or a script's limit ended
        self.failures: list[str] = []  # why each failed instance ended, one sentence each
        self.output = output or (lambda line: print(f"[{robot}] {line}", flush=True))
        self._javascript: JavaScript | None = None  # made when a first script needs it
        self.watch: watchdog.Watch | None = None  # made when a first Python script runs
        self.time = EngineTime.of(clock)  # None: computing takes no simulated time
        self._frame: Frame | None = None  # the instance frame installed in the variables
        self.compensating: set[RunScope] = set()  # compensations running (compensation.py)
        self.activities = RunningActivities(robot, self.tag)  # started, not yet ended

    def _deploy(self, process: Process | ScopePlan) -> ScopePlan:
        if isinstance(process, ScopePlan):
            return process
        return deploy(process, skills=self.skills, library=self.library)

    def __repr__(self) -> str:
        return f"Engine({self.robot.name!r}, {self.plan.process.describe()!r})"

    # -- life cycle ----------------------------------------------------------------------------

    @property
    def idle(self) -> bool:
        """No process instance is running or about to (one may still start on a signal or
        a timer)."""
        return not self._roots and not self._starting and not self._work

    @property
    def ended(self) -> bool:
        """Nothing runs and nothing can start an instance any more."""
        return self.started and self.idle and (self.stopped or not self._start_disarms)

    @property
    def next_timer(self) -> float | None:
        """When the next armed timer fires (a timer start event included), or None."""
        return self.triggers.next_timer()

    def where(self) -> list[str]:
        """The elements where this robot's tokens are, innermost scopes included (what a
        run that stops early reports)."""
        places: list[str] = []
        scopes = list(self._roots)
        while scopes:
            scope = scopes.pop(0)
            for token in sorted(scope.tokens, key=lambda t: t.node.id):
                node = token.node.node
                places.append(f"{node.kind} {node.describe()}")
                if token.child is not None:
                    scopes.append(token.child)
        return places

    def start(self) -> None:
        """Arm the start events; an instance for the none start events begins at the clock's
        next step (so every engine of a mission subscribes before anyone throws)."""
        if self.started and not self.stopped:
            return
        self.started, self.stopped = True, False
        for start in self.plan.triggered_starts:
            assert start.trigger is not None  # the deployer gives every one its trigger
            self._start_disarms.append(
                self.triggers.arm(start.trigger, self._starter(start), repeat=True)
            )
        if self.plan.starts:
            self._starting += 1
            self.clock.call_soon(self._first_instance)

    def _first_instance(self) -> None:
        self._starting -= 1
        if not self.stopped:
            self.call(self.start_instance)

    def start_instance(self) -> None:
        """Start one more instance at the none start events, now."""
        root = self.open_scope(self.plan, None, None)
        for start in self.plan.starts:
            self.push(self.new_token(root, start), start)

    def _starter(self, start: NodePlan) -> Callable[[Envelope | None], None]:
        def fire(envelope: Envelope | None) -> None:
            if self.stopped:
                return
            root = self.open_scope(self.plan, None, None)
            caught(self, self.new_token(root, start), start, envelope)

        return fire

    def stop(self, *, safe: bool = True, then: Callable[[], Any] | None = None) -> None:
        """End every instance -- after its safe-state handler ran, when ``safe`` and the model
        has one -- and start nothing more; ``then`` runs once everything has ended."""
        self.stopped = True
        for disarm in self._start_disarms:
            disarm()
        self._start_disarms.clear()
        if then is not None:
            self._when_idle.append(then)
        self.call(lambda: self._stop_all(safe))

    def _stop_all(self, safe: bool) -> None:
        for root in list(self._roots):
            self.kill_scope(root, safe=safe)

    def replace(self, process: Process | ScopePlan) -> None:
        """Run ``process`` from now on instead: the running instances end first (their
        safe-state handler runs), then the new process starts."""
        plan = self._deploy(process)

        def restart() -> None:
            self.plan = plan
            self.data.keep_unset = speaks_javascript(plan)
            self.robot.close()
            if self._javascript is not None:
                self._javascript.close()
            self.start()

        self.stop(safe=True, then=restart)

    def when_idle(self, callback: Callable[[], Any]) -> None:
        """Call ``callback`` once no instance runs (now, if none does)."""
        self._when_idle.append(callback)
        self._idle_check()

    def set_variables(self, **values: Any) -> None:
        """Set variables from outside (the simulation, a test); conditional events that read
        them are re-evaluated."""
        self.robot.set(**values)

    # -- the work loop ---------------------------------------------------------------------------

    def call(self, work: Callable[[], Any]) -> None:
        self._work.append(work)
        if not self._busy:
            self._drain()

    def push(self, token: Token, node: NodePlan) -> None:
        self.call(lambda: self.advance(token, node))

    def _drain(self) -> None:
        self._busy = True
        self._steps = 0
        computing = False
        try:
            while self._work:
                if self.time is not None and self.time.wait(self._drain):
                    computing = True  # what is queued waits until the clock catches up
                    break
                if self._frame is not None:
                    self.enter(None)  # work runs on the process's variables unless it says
                self._work.popleft()()
                if not self._work and self.inclusive:
                    recheck_joins(self)
        except BaseException:
            self._work.clear()
            raise
        finally:
            self._busy = computing
            if self._frame is not None:
                self.enter(None)  # what reads the variables from outside sees the robot's
        if not computing:
            self._idle_check()

    def _idle_check(self) -> None:
        if self._roots or not self._when_idle or self._busy:
            return
        waiting, self._when_idle = self._when_idle, []
        for then in waiting:
            then()

    def advance(self, token: Token, node: NodePlan | None) -> None:
        """Move ``token`` from ``node`` on until it has to wait."""
        behaviours = self._BEHAVIOURS  # a local: this loop is the engine's hot path
        if token.frame is not self._frame:
            self.enter(token.frame)
        while node is not None and token.alive:
            token.node = node
            self._steps += 1
            if self._steps > MAX_STEPS:
                raise ModelError(
                    f"robot {self.robot.name}: {node.node.kind} {node.node.describe()} is in a "
                    f"loop that ran {MAX_STEPS} steps without waiting for anything"
                )
            if self.time is not None:
                node = self._timed_step(token, node, self.time)
                continue
            node = behaviours[node.behaviour](self, token, node)

    def _timed_step(self, token: Token, node: NodePlan, time: EngineTime) -> NodePlan | None:
        """Run one step, charged to the clock; while the engine computes, the token's next
        step waits at the head of the queue (None: it waits or has gone)."""
        began = time.begin()
        try:
            next_node = self._BEHAVIOURS[node.behaviour](self, token, node)
        finally:
            computing = time.spent("step", began)
        if computing and next_node is not None and token.alive:
            self._work.appendleft(lambda: self.advance(token, next_node))
            return None
        return next_node

    def charged(self, kind: str) -> contextlib.AbstractContextManager[None]:
        """A ``with`` block of work of ``kind`` (script, condition) charged to the clock."""
        return _FREE if self.time is None else self.time.work(kind)

    # -- instance frames ---------------------------------------------------------------------

    def enter(self, frame: Frame | None) -> None:
        """Install ``frame`` (and the frames around it) in the variables; None: only the
        process's own variables."""
        if frame is not self._frame:
            install(self.variables, self._frame, frame)
            self._frame = frame

    def enter_token(self, token: Token) -> None:
        if token.frame is not self._frame:
            self.enter(token.frame)

    # -- tokens and scopes ---------------------------------------------------------------------

    def new_token(self, scope: RunScope, node: NodePlan) -> Token:
        token = Token(scope, node)
        scope.tokens.add(token)
        return token

    def open_scope(
        self, plan: ScopePlan, parent: RunScope | None, holder: Token | None
    ) -> RunScope:
        scope = RunScope(plan, parent, holder)
        if parent is None:
            self._roots.append(scope)
        if holder is not None:
            holder.child = scope
        self.data.declare(plan.data_objects)
        for esp in plan.event_subprocesses:
            arm_event_subprocess(self, scope, esp)
        return scope

    def consume(self, token: Token) -> None:
        token.alive = False
        scope = token.scope
        scope.tokens.discard(token)
        if token.instance is not None:
            instance_done(self, token, token.instance)
        elif not scope.tokens and not scope.ended:
            self.close_scope(scope)

    def cancel(self, token: Token) -> None:
        """Stop what ``token`` does (skills cancelled, timers and subscriptions dropped)."""
        if not token.alive:
            return
        token.alive = False
        token.scope.tokens.discard(token)
        waiting = token.scope.joins.get(token.node.id)
        if waiting and token in waiting:
            waiting.remove(token)
        self.disarm(token)
        if token.child is not None:
            self.cancel_scope(token.child)
        self.activities.end(token, Lifecycle.ABORT)  # after its inner activities: they ended first

    def disarm(self, token: Token) -> None:
        token.generation += 1  # whatever fires for the old wait from now on is stale
        for undo in (*token.waits, *token.boundaries):
            undo()
        token.waits.clear()
        token.boundaries.clear()

    def cancel_scope(self, scope: RunScope) -> None:
        if self.compensating:
            self._cancel_compensations(scope)
        scope.ended = True
        for disarm in scope.armed.values():
            disarm()
        scope.armed.clear()
        for token in list(scope.tokens):
            self.cancel(token)
        self.inclusive.discard(scope)

    def _cancel_compensations(self, scope: RunScope) -> None:
        """A scope that ends takes the compensations running inside it along."""
        for place in list(self.compensating):
            outer = place.parent
            while outer is not None and outer is not scope:
                outer = outer.parent
            if outer is scope:
                self.compensating.discard(place)
                place.on_close = None  # cancelled: nothing waits for it any more
                self.cancel_scope(place)

    def close_scope(self, scope: RunScope) -> None:
        """``scope`` has no token left: it completes."""
        self.cancel_scope(scope)
        if scope.on_close is not None:  # a compensation ran in it
            scope.on_close()
            return
        if scope.holder is None:
            self._roots.remove(scope)
            if scope.failed:
                self.failed += 1
            else:
                self.completed += 1
        elif scope.holder.alive:
            activity_done(self, scope.holder)

    def kill_scope(self, scope: RunScope, *, safe: bool) -> None:
        """End every token of ``scope``; a top-level scope with a safe-state handler runs it
        first (thesis 4.1.3)."""
        handler = scope.plan.safe_state if safe and scope.holder is None else None
        if handler is not None and not scope.safe:
            event_subprocess(self, scope, handler, None, interrupting=True, triggered=False)
            return
        for token in list(scope.tokens):
            self.cancel(token)
        if not scope.ended:
            self.close_scope(scope)

    # -- leaving a node ----------------------------------------------------------------------------

    def follow(self, token: Token, flows: list[FlowPlan]) -> NodePlan | None:
        """Send ``token`` along ``flows`` (more than one: new tokens for the others)."""
        if not flows:
            self.consume(token)
            return None
        for flow in flows[1:]:
            other = self.new_token(token.scope, flow.target)
            other.flow = flow.id
            self.push(other, flow.target)
        token.flow = flows[0].id
        return flows[0].target

    def taken(self, node: NodePlan, *, first: bool) -> list[FlowPlan]:
        """The outgoing flows whose condition holds (the default flow when none does)."""
        taken = []
        for flow in node.outgoing:
            if flow is node.default:
                continue
            if flow.condition is None or self.conditions.holds(flow.condition, flow.id):
                taken.append(flow)
                if first:
                    break
        if not taken and node.default is not None:
            taken.append(node.default)
        return taken

    def go_on(self, token: Token, node: NodePlan) -> None:
        """Queue ``token``'s move out of ``node`` (from a callback, not a behaviour)."""
        next_node = self.follow(token, self.taken(node, first=False))
        if next_node is not None:
            self.push(token, next_node)

    def fail(self, token: Token, sentence: str) -> None:
        """End ``token``'s process instance as failed, saying why."""
        root = token.scope
        while root.parent is not None:
            root = root.parent
        self.failures.append(sentence)
        root.failed = True
        self.kill_scope(root, safe=False)

    @property
    def javascript(self) -> JavaScript:
        """This robot's JavaScript runtime (its variables are the robot's)."""
        if self._javascript is None:
            self._javascript = JavaScript(
                self.robot.name,
                self.bus,
                self.variables,
                schedule=self.call,
                changed=self.changed,
                output=self.output,
            )
        return self._javascript

    def watching(self) -> watchdog.Watch:
        """This engine's stamp for the Python scripts' time limit, made at its first script."""
        self.watch = watchdog.watch()
        return self.watch

    @property
    def activity_observer(self) -> ActivityObserver | None:
        """Told of every activity instance as it starts and ends, apart from the tags."""
        return self.activities.observer

    @activity_observer.setter
    def activity_observer(self, observer: ActivityObserver | None) -> None:
        self.activities.observer = observer

    def changed(self, names: Iterable[str]) -> None:
        self.triggers.changed(names)
