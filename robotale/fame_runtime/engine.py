"""The token engine: one per robot, running that robot's process (BPMN 2.0 section 13).

Tokens move through the process as far as they can without waiting; a token waits at a skill
that takes time, a catching event, a sub-process, a join. Everything that wakes a token up --
a message on the bus, a timer, a skill's ``done``, a variable change satisfying a condition --
is queued and run by the engine's own loop, never inside another engine's step or inside the
bus. Every activity start and completion, every signal thrown or caught, every timer, error
and conditional event becomes a :class:`~robotale.fame_runtime.tags.Tag`; an activity that is
interrupted or cancelled ends with an ``ate_abort`` tag instead of ``complete``.

See ``docs/fame_runtime.md`` for the API and the exact semantics.
"""

from __future__ import annotations

import builtins
import contextlib
import types
from collections import deque
from collections.abc import Callable, Iterable, Mapping
from pathlib import Path
from threading import get_ident
from typing import Any, ClassVar

from robotale.errors import ModelError
from robotale.fame_runtime import watchdog
from robotale.fame_runtime.bus import Bus, Envelope
from robotale.fame_runtime.clock import Clock, EngineTime
from robotale.fame_runtime.data import Data
from robotale.fame_runtime.expressions import BpmnError, Compiled
from robotale.fame_runtime.javascript import Completion, JavaScript, ScriptFailure, ScriptLimit
from robotale.fame_runtime.library import Library
from robotale.fame_runtime.model import JAVASCRIPT, Process
from robotale.fame_runtime.plan import (
    FlowPlan,
    NodePlan,
    ScopePlan,
    deploy,
    reachable_flows,
    speaks_javascript,
)
from robotale.fame_runtime.robot import RobotHandle
from robotale.fame_runtime.skills import Skill
from robotale.fame_runtime.tags import ABORT, COMPLETE, START, Tagger, TagSink, payload_text
from robotale.fame_runtime.triggers import Triggers
from robotale.fame_runtime.watchdog import MEASURE, ScriptTimeout

#: steps one engine may take without its clock moving on: more means a loop with no wait
MAX_STEPS = 1_000_000

#: runs a token at a node (engine, token, node) and returns where it goes next (None: it waits
#: or is gone)
Behaviour = Callable[["Engine", "_Token", NodePlan], "NodePlan | None"]

#: values a script leaves behind that are not variables (``import math``, functions it defines)
_NOT_VARIABLES = (types.ModuleType, types.FunctionType, type)

#: what charging work costs when the engine's clock charges nothing
_FREE = contextlib.nullcontext()

#: told of every activity instance as it starts and ends (robot, instance number, activity,
#: ``start`` / ``completed`` / ``interrupted`` / ``cancelled``), apart from the tags: a
#: simulation's ground truth numbers instances, which tags do not
ActivityObserver = Callable[[str, int, str, str], None]


_ABSENT = object()  # a variable a frame shadows that had no value outside it


class _Frame:
    """The variables of one multi-instance instance that are its own (BPMN 2.0 section
    10.3.8: every instance has its own ``loopCounter``, input item and output item). The
    engine keeps one variables dict for a robot; before it runs a token of an instance it
    installs that instance's frame (its values in, the outer ones kept aside) and takes it
    out again afterwards, so instances running side by side never see each other's item."""

    __slots__ = ("outer", "parent", "values")

    def __init__(self, parent: _Frame | None, values: dict[str, Any]) -> None:
        self.parent = parent
        self.values = values  # the instance's own values while it is not installed
        self.outer: dict[str, Any] = {}  # what the variables held before it was installed

    def chain(self) -> list[_Frame]:
        """This frame and the frames around it, outermost first."""
        frames, frame = [], self
        while frame is not None:
            frames.append(frame)
            frame = frame.parent
        return frames[::-1]


class _Token:
    __slots__ = (
        "alive",
        "boundaries",
        "child",
        "flow",
        "frame",
        "generation",
        "instance",
        "node",
        "scope",
        "waits",
    )

    def __init__(self, scope: _Scope, node: NodePlan) -> None:
        self.frame: _Frame | None = scope.frame  # the instance variables it runs with
        self.scope = scope
        self.node = node
        self.flow = ""  # the sequence flow it arrived by (joins count them)
        self.waits: list[Callable[[], Any]] = []  # undo what it waits for
        self.boundaries: list[Callable[[], Any]] = []  # disarm its activity's boundary events
        self.child: _Scope | None = None
        self.alive = True
        self.generation = 0  # stale skill completions are ignored
        self.instance: _Loop | None = None  # the loop this token runs one instance of


class _Loop:
    """One running loop or multi-instance activity: the token waiting at it (``holder``)
    and its instances."""

    __slots__ = ("active", "completed", "holder", "items", "next", "node", "outputs")

    def __init__(self, holder: _Token, node: NodePlan, items: list[Any] | None) -> None:
        self.holder = holder
        self.node = node
        self.items = items  # one per instance; None: a standard loop (until its condition)
        self.next = 0  # the index of the next instance to start
        self.completed = 0
        self.active: dict[_Token, int] = {}  # running instance -> its index
        self.outputs: dict[int, Any] = {}  # instance index -> its output item


class _Done:
    """An activity that completed and may be compensated (BPMN 2.0 section 10.6.5): the
    scope it completed in, its instance frame, and for a sub-process its finished content."""

    __slots__ = ("child", "frame", "node", "scope")

    def __init__(self, node: NodePlan, scope: _Scope, frame: _Frame | None, child) -> None:
        self.node, self.scope, self.frame = node, scope, frame
        self.child: _Scope | None = child


class _Scope:
    """A running process, called process, sub-process or event sub-process."""

    __slots__ = (
        "armed",
        "depth",
        "done",
        "ended",
        "failed",
        "frame",
        "holder",
        "joins",
        "on_close",
        "parent",
        "plan",
        "safe",
        "tokens",
    )

    def __init__(self, plan: ScopePlan, parent: _Scope | None, holder: _Token | None) -> None:
        self.plan = plan
        self.parent = parent
        self.holder = holder  # the token of the activity this scope runs inside
        self.frame = holder.frame if holder is not None else None
        self.depth = parent.depth + 1 if parent else 0
        self.tokens: set[_Token] = set()
        self.joins: dict[str, list[_Token]] = {}
        self.armed: dict[str, Callable[[], Any]] = {}  # event sub-process id -> disarm
        self.ended = False
        self.failed = False  # a top-level scope ended by an uncaught error or a model error
        self.safe = False  # its safe-state handler runs before it ends
        self.done: list[_Done] = []  # its completed activities to compensate, oldest first
        self.on_close: Callable[[], Any] | None = None  # a compensation's: what comes next


class Engine:
    """Runs one robot's process.

    ``process`` is a parsed :class:`~robotale.fame_runtime.model.Process` (or an already
    deployed plan); ``skills`` maps called-element names to Python skills; ``library`` is a
    folder of .bpmn building blocks for call activities; ``variables`` are initial variables
    (they win over the data objects' literal values); ``tag_sink`` receives every tag;
    ``output`` prints what JavaScript scripts ``console.log`` (default: standard output, each
    line prefixed with the robot's name).
    """

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
        self.robot = RobotHandle(robot, robot_type, bus, clock, self.variables, self._changed)
        self.env: dict[str, Any] = {
            "__builtins__": builtins,
            "robot": self.robot,
            "BpmnError": BpmnError,
        }
        self.data = Data(robot, self.variables, self.env, self._changed)
        self.data.keep_unset = speaks_javascript(self.plan)
        self._tag = Tagger(robot, clock, tag_sink, bus)
        self.triggers = Triggers(
            robot, bus, clock, self._call, self._value, self.env, self.variables
        )
        self._work: deque[Callable[[], Any]] = deque()  # first queued, first run
        self._busy = False
        self._steps = 0
        self._roots: list[_Scope] = []
        self._start_disarms: list[Callable[[], Any]] = []
        self._inclusive: set[_Scope] = set()
        self._when_idle: list[Callable[[], Any]] = []
        self._starting = 0  # none-start instances scheduled but not begun
        self.started = False
        self.stopped = False
        self.completed = 0  # process instances that ended normally
        self.failed = 0  # process instances an uncaught error or a script's limit ended
        self.failures: list[str] = []  # why each failed instance ended, one sentence each
        self.output = output or (lambda line: print(f"[{robot}] {line}", flush=True))
        self._javascript: JavaScript | None = None  # made when a first script needs it
        self._watch: watchdog.Watch | None = None  # made when a first Python script runs
        self._time = EngineTime.of(clock)  # None: computing takes no simulated time
        self._frame: _Frame | None = None  # the instance frame installed in the variables
        self._compensating: set[_Scope] = set()  # compensations running (see _compensate_one)
        #: the activities started and not yet ended, by the token running each: the token's
        #: activity label and instance number
        self._running: dict[_Token, tuple[str, int]] = {}
        self._instances = 0
        #: how a cancel ends the activities it reaches: ``interrupted`` while an interrupting
        #: boundary event or event sub-process takes over, else ``cancelled``
        self._ending = "cancelled"
        self.activity_observer: ActivityObserver | None = None

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
            self._start_disarms.append(
                self.triggers.arm(start.trigger, self._starter(start), repeat=True)
            )
        if self.plan.starts:
            self._starting += 1
            self.clock.call_soon(self._first_instance)

    def _first_instance(self) -> None:
        self._starting -= 1
        if not self.stopped:
            self._call(self.start_instance)

    def start_instance(self) -> None:
        """Start one more instance at the none start events, now."""
        root = self._open(self.plan, None, None)
        for start in self.plan.starts:
            self._push(self._new_token(root, start), start)

    def _starter(self, start: NodePlan) -> Callable[[Envelope | None], None]:
        def fire(envelope: Envelope | None) -> None:
            if self.stopped:
                return
            root = self._open(self.plan, None, None)
            self._caught(self._new_token(root, start), start, envelope)

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
        self._call(lambda: self._stop_all(safe))

    def _stop_all(self, safe: bool) -> None:
        for root in list(self._roots):
            self._kill(root, safe=safe)

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

    def _call(self, work: Callable[[], Any]) -> None:
        self._work.append(work)
        if not self._busy:
            self._drain()

    def _push(self, token: _Token, node: NodePlan) -> None:
        self._call(lambda: self._advance(token, node))

    def _drain(self) -> None:
        self._busy = True
        self._steps = 0
        computing = False
        try:
            while self._work:
                if self._time is not None and self._time.wait(self._drain):
                    computing = True  # what is queued waits until the clock catches up
                    break
                if self._frame is not None:
                    self._enter(None)  # work runs on the process's variables unless it says
                self._work.popleft()()
                if not self._work and self._inclusive:
                    self._recheck_joins()
        except BaseException:
            self._work.clear()
            raise
        finally:
            self._busy = computing
            if self._frame is not None:
                self._enter(None)  # what reads the variables from outside sees the robot's
        if not computing:
            self._idle_check()

    def _idle_check(self) -> None:
        if self._roots or not self._when_idle or self._busy:
            return
        waiting, self._when_idle = self._when_idle, []
        for then in waiting:
            then()

    def _advance(self, token: _Token, node: NodePlan | None) -> None:
        """Move ``token`` from ``node`` on until it has to wait."""
        behaviours = self._BEHAVIOURS  # a local: this loop is the engine's hot path
        if token.frame is not self._frame:
            self._enter(token.frame)
        while node is not None and token.alive:
            token.node = node
            self._steps += 1
            if self._steps > MAX_STEPS:
                raise ModelError(
                    f"robot {self.robot.name}: {node.node.kind} {node.node.describe()} is in a "
                    f"loop that ran {MAX_STEPS} steps without waiting for anything"
                )
            if self._time is not None:
                node = self._timed_step(token, node)
                continue
            node = behaviours[node.behaviour](self, token, node)

    def _timed_step(self, token: _Token, node: NodePlan) -> NodePlan | None:
        """Run one step, charged to the clock; while the engine computes, the token's next
        step waits at the head of the queue (None: it waits or has gone)."""
        began = self._time.begin()
        try:
            next_node = self._BEHAVIOURS[node.behaviour](self, token, node)
        finally:
            computing = self._time.spent("step", began)
        if computing and next_node is not None and token.alive:
            self._work.appendleft(lambda: self._advance(token, next_node))
            return None
        return next_node

    def _charged(self, kind: str) -> contextlib.AbstractContextManager[None]:
        """A ``with`` block of work of ``kind`` (script, condition) charged to the clock."""
        return _FREE if self._time is None else self._time.work(kind)

    # -- instance frames ---------------------------------------------------------------------

    def _enter(self, frame: _Frame | None) -> None:
        """Install ``frame`` (and the frames around it) in the variables; None: only the
        process's own variables."""
        if frame is self._frame:
            return
        current = self._frame.chain() if self._frame is not None else []
        wanted = frame.chain() if frame is not None else []
        common = 0
        while common < min(len(current), len(wanted)) and current[common] is wanted[common]:
            common += 1
        variables = self.variables
        for leaving in reversed(current[common:]):
            for name in leaving.values:
                leaving.values[name] = variables.get(name, _ABSENT)
                outer = leaving.outer.pop(name)
                if outer is _ABSENT:
                    variables.pop(name, None)
                else:
                    variables[name] = outer
        for entering in wanted[common:]:
            for name, value in entering.values.items():
                entering.outer[name] = variables.get(name, _ABSENT)
                if value is _ABSENT:
                    variables.pop(name, None)
                else:
                    variables[name] = value
        self._frame = frame

    def _enter_token(self, token: _Token) -> None:
        if token.frame is not self._frame:
            self._enter(token.frame)

    # -- tokens and scopes ---------------------------------------------------------------------

    def _new_token(self, scope: _Scope, node: NodePlan) -> _Token:
        token = _Token(scope, node)
        scope.tokens.add(token)
        return token

    def _open(self, plan: ScopePlan, parent: _Scope | None, holder: _Token | None) -> _Scope:
        scope = _Scope(plan, parent, holder)
        if parent is None:
            self._roots.append(scope)
        if holder is not None:
            holder.child = scope
        self.data.declare(plan.data_objects)
        for esp in plan.event_subprocesses:
            self._arm_event_subprocess(scope, esp)
        return scope

    def _consume(self, token: _Token) -> None:
        token.alive = False
        scope = token.scope
        scope.tokens.discard(token)
        if token.instance is not None:
            self._instance_done(token)
        elif not scope.tokens and not scope.ended:
            self._close(scope)

    def _cancel(self, token: _Token) -> None:
        """Stop what ``token`` does (skills cancelled, timers and subscriptions dropped)."""
        if not token.alive:
            return
        token.alive = False
        token.scope.tokens.discard(token)
        waiting = token.scope.joins.get(token.node.id)
        if waiting and token in waiting:
            waiting.remove(token)
        self._disarm(token)
        if token.child is not None:
            self._cancel_scope(token.child)
        self._end(token, ABORT)  # after its inner activities: they ended first

    def _disarm(self, token: _Token) -> None:
        token.generation += 1  # whatever fires for the old wait from now on is stale
        for undo in (*token.waits, *token.boundaries):
            undo()
        token.waits.clear()
        token.boundaries.clear()

    def _cancel_scope(self, scope: _Scope) -> None:
        if self._compensating:
            self._cancel_compensations(scope)
        scope.ended = True
        for disarm in scope.armed.values():
            disarm()
        scope.armed.clear()
        for token in list(scope.tokens):
            self._cancel(token)
        self._inclusive.discard(scope)

    def _cancel_compensations(self, scope: _Scope) -> None:
        """A scope that ends takes the compensations running inside it along."""
        for place in list(self._compensating):
            outer = place.parent
            while outer is not None and outer is not scope:
                outer = outer.parent
            if outer is scope:
                self._compensating.discard(place)
                place.on_close = None  # cancelled: nothing waits for it any more
                self._cancel_scope(place)

    def _close(self, scope: _Scope) -> None:
        """``scope`` has no token left: it completes."""
        self._cancel_scope(scope)
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
            self._activity_done(scope.holder)

    def _kill(self, scope: _Scope, *, safe: bool) -> None:
        """End every token of ``scope``; a top-level scope with a safe-state handler runs it
        first (thesis 4.1.3)."""
        handler = scope.plan.safe_state if safe and scope.holder is None else None
        if handler is not None and not scope.safe:
            self._event_subprocess(scope, handler, None, interrupting=True, triggered=False)
            return
        for token in list(scope.tokens):
            self._cancel(token)
        if not scope.ended:
            self._close(scope)

    # -- leaving a node ----------------------------------------------------------------------------

    def _follow(self, token: _Token, flows: list[FlowPlan]) -> NodePlan | None:
        """Send ``token`` along ``flows`` (more than one: new tokens for the others)."""
        if not flows:
            self._consume(token)
            return None
        for flow in flows[1:]:
            other = self._new_token(token.scope, flow.target)
            other.flow = flow.id
            self._push(other, flow.target)
        token.flow = flows[0].id
        return flows[0].target

    def _taken(self, node: NodePlan, *, first: bool) -> list[FlowPlan]:
        """The outgoing flows whose condition holds (the default flow when none does)."""
        taken = []
        for flow in node.outgoing:
            if flow is node.default:
                continue
            if flow.condition is None or self._condition(flow.condition, flow.id):
                taken.append(flow)
                if first:
                    break
        if not taken and node.default is not None:
            taken.append(node.default)
        return taken

    @property
    def javascript(self) -> JavaScript:
        """This robot's JavaScript runtime (its variables are the robot's)."""
        if self._javascript is None:
            self._javascript = JavaScript(
                self.robot.name,
                self.bus,
                self.variables,
                schedule=self._call,
                changed=self._changed,
                output=self.output,
            )
        return self._javascript

    def _condition(self, condition: Compiled, where: str) -> bool:
        return bool(self._evaluate(condition, where))

    def _evaluate(self, condition: Compiled, where: str) -> Any:
        """The value of a condition or expression (a loop's cardinality), errors explained."""
        try:
            with self._charged("condition"):
                if condition.language == JAVASCRIPT:
                    return self.javascript.condition(condition.source)
                return eval(condition.code, self.env, self.variables)
        except BpmnError:
            raise
        except ScriptFailure as failure:
            raise ModelError(
                f"robot {self.robot.name}: the JavaScript condition of {where} failed: "
                f"{failure.text}"
            ) from None
        except Exception as error:
            raise ModelError(
                f"robot {self.robot.name}: the condition of {where} ({condition.source}) "
                f"failed: {type(error).__name__}: {error}"
            ) from error

    def _value(self, condition: Compiled) -> Any:
        """A conditional event's condition; one reading a variable nobody set yet is false
        (it cannot have become true), unlike a gateway's, where that is a model error."""
        try:
            if condition.language == JAVASCRIPT:
                return self._condition(condition, "a conditional event")
            with self._charged("condition"):
                return eval(condition.code, self.env, self.variables)
        except NameError:
            return False
        except Exception:
            return self._condition(condition, "a conditional event")

    # -- behaviours: each runs a token at a node and returns where it goes next --------------

    def _run_start(self, token: _Token, node: NodePlan) -> NodePlan | None:
        return self._follow(token, self._taken(node, first=False))

    def _run_pass(self, token: _Token, node: NodePlan) -> NodePlan | None:
        if node.throw is not None and node.throw.kind == "compensate":
            if not self._throw_compensation(token, node, lambda: self._go_on(token, node)):
                return None  # it goes on once the compensation is done
        elif node.throw is not None and node.throw.kind == "escalation":
            if not self._escalate(token, node):
                return None  # an interrupting catcher cancelled the thrower
        elif node.throw is not None:
            self._publish(node)
        return self._follow(token, self._taken(node, first=False))

    def _run_end(self, token: _Token, node: NodePlan) -> NodePlan | None:
        kind = node.throw.kind if node.throw is not None else "none"
        if kind in ("signal", "message"):
            self._publish(node)
        if kind == "error":
            self._throw_error(token, node.throw.topic)  # the catching event is tagged
            return None
        if kind == "escalation" and not self._escalate(token, node):
            return None
        if kind == "compensate" and not self._throw_compensation(
            token, node, lambda: self._consume(token)
        ):
            return None  # it ends once the compensation is done
        self._consume(token)
        return None

    def _run_terminate(self, token: _Token, node: NodePlan) -> NodePlan | None:
        self._kill(token.scope, safe=True)
        return None

    def _run_task(self, token: _Token, node: NodePlan) -> NodePlan | None:
        self._begin(token, node.label)
        self.data.inputs(node)
        self._end(token, COMPLETE)
        self._compensable(token, node)
        self.data.outputs(node, {})
        return self._follow(token, self._taken(node, first=False))

    def _run_script(self, token: _Token, node: NodePlan) -> NodePlan | None:
        self._begin(token, node.label)
        self.data.inputs(node)
        if node.script is not None and node.script.language == JAVASCRIPT:
            return self._run_javascript(token, node)
        if node.script is not None:
            try:
                self._exec(node)
            except BpmnError as error:
                self._throw_error(token, error.name)
                return None
            except MemoryError:
                self._script_limit(token, node, "ran out of the memory of the Python process")
                return None
            except ScriptTimeout:
                limit = self._watch.limit if self._watch is not None else watchdog.TIME_LIMIT
                self._script_limit(
                    token, node, f"ran longer than its time limit of {limit:g} s of {MEASURE}"
                )
                return None
        self._end(token, COMPLETE)
        self._compensable(token, node)
        self.data.outputs(node, {})
        return self._follow(token, self._taken(node, first=False))

    def _exec(self, node: NodePlan) -> None:
        script = node.script
        watch = self._watch or self._watching()
        try:
            with self._charged("script"):
                # the watchdog's stamp: a fresh tuple per run, told apart by identity
                watch.running = (node, get_ident())
                try:
                    exec(script.code, self.env, self.variables)
                finally:
                    watch.running = None
                    if watch.fired:  # the watchdog stopped it, or is about to
                        watch.settle()
        except (BpmnError, MemoryError, ScriptTimeout):
            raise
        except Exception as error:
            raise ModelError(
                f"robot {self.robot.name}: script task {node.node.describe()} failed: "
                f"{type(error).__name__}: {error}"
            ) from error
        for name in script.writes:
            if isinstance(self.variables.get(name), _NOT_VARIABLES):
                del self.variables[name]
        self._changed(script.writes)

    def _watching(self) -> watchdog.Watch:
        """This engine's stamp for the Python scripts' time limit, made at its first script."""
        self._watch = watchdog.watch()
        return self._watch

    def _run_javascript(self, token: _Token, node: NodePlan) -> NodePlan | None:
        """A JavaScript script task completes when it calls ``next``: at once, like a Python
        script, or later from a callback, its token waiting like a skill's meanwhile (with its
        boundary events armed)."""
        generation = token.generation
        javascript = self._javascript or self.javascript
        try:
            if self._time is None:  # nothing to charge: the hot path spares the with block
                now = javascript.run_task(
                    node.script.source, lambda: self._script_done(token, generation)
                )
            else:
                with self._charged("script"):
                    now = javascript.run_task(
                        node.script.source, lambda: self._script_done(token, generation)
                    )
        except ScriptFailure as failure:
            self._throw_error(token, f"script task {node.node.describe()}: {failure.text}")
            return None
        except ScriptLimit as limit:
            self._script_limit(token, node, limit.what)
            return None
        if now is None:
            self._arm_boundaries(token, node)
            return None
        if now[0] is not None:
            self._throw_error(token, now[0])
            return None
        self._end(token, COMPLETE)
        self._compensable(token, node)
        self.data.outputs(node, {})
        return self._follow(token, self._taken(node, first=False))

    def _script_done(self, token: _Token, generation: int) -> Completion:
        """What a script task's ``next`` calls once its run has returned: the task completes
        (or throws) in a later step, as a skill's does."""

        def done(error: str | None, _value: Any) -> None:
            outcome = None if error is None else BpmnError(error)
            self._call(lambda: self._skill_done(token, generation, outcome))

        return done

    def _run_skill(self, token: _Token, node: NodePlan) -> NodePlan | None:
        self._begin(token, node.label)
        inputs = self.data.inputs(node)
        self._arm_boundaries(token, node)
        generation = token.generation

        def done(outputs: Mapping[str, Any] | BpmnError | None = None) -> None:
            self._call(lambda: self._skill_done(token, generation, outputs))

        try:
            cancel = self.skills[node.skill](self.robot, types.MappingProxyType(inputs), done)
        except BpmnError as error:
            self._throw_error(token, error.name)
            return None
        except Exception as error:
            raise ModelError(
                f"robot {self.robot.name}: skill {node.skill!r} of call activity "
                f"{node.node.describe()} failed: {type(error).__name__}: {error}"
            ) from error
        if callable(cancel):
            token.waits.append(cancel)
        return None

    def _skill_done(self, token: _Token, generation: int, outputs: Any) -> None:
        if not token.alive or token.generation != generation:
            return  # cancelled meanwhile, or called twice
        self._enter_token(token)
        token.waits.clear()  # the skill ended: nothing to cancel any more
        if isinstance(outputs, BpmnError):
            self._throw_error(token, outputs.name)
            return
        values = dict(outputs or {})
        self.data.set(values)
        self._activity_done(token, values)

    def _run_call(self, token: _Token, node: NodePlan) -> NodePlan | None:
        self._begin(token, node.label)
        self.data.inputs(node)
        self._arm_boundaries(token, node)
        child = self._open(node.child, token.scope, token)
        for start in node.child.starts:
            self._push(self._new_token(child, start), start)
        if not node.child.starts:
            self._close(child)
        return None

    def _activity_done(self, token: _Token, outputs: Mapping[str, Any] | None = None) -> None:
        """A waiting activity (skill, call, sub-process, event sub-process) completed."""
        self._enter_token(token)
        node = token.node
        child, token.child = token.child, None
        self._disarm(token)
        self._end(token, COMPLETE)
        if node.behaviour == "event_subprocess":
            self._consume(token)
            return
        self._compensable(token, node, child)
        self.data.outputs(node, outputs or {})
        self._go_on(token, node)

    def _go_on(self, token: _Token, node: NodePlan) -> None:
        """Queue ``token``'s move out of ``node`` (from a callback, not a behaviour)."""
        next_node = self._follow(token, self._taken(node, first=False))
        if next_node is not None:
            self._push(token, next_node)

    def _run_catch(self, token: _Token, node: NodePlan) -> NodePlan | None:
        token.waits.append(self.triggers.arm(node.trigger, self._waker(token, node)))
        self._arm_boundaries(token, node)  # a receive task may have boundary events
        return None

    def _waker(self, token: _Token, node: NodePlan) -> Callable[[Envelope | None], None]:
        generation = token.generation

        def fire(envelope: Envelope | None) -> None:
            if token.alive and token.generation == generation:
                self._disarm(token)
                self._caught(token, node, envelope)

        return fire

    def _caught(self, token: _Token, node: NodePlan, envelope: Envelope | None) -> None:
        """A catching event fired for ``token``: tag it, store the message, move on."""
        self._enter_token(token)
        values = self._received(node, envelope)
        self.data.outputs(node, values)
        token.node = node
        self._go_on(token, node)

    def _run_exclusive_gateway(self, token: _Token, node: NodePlan) -> NodePlan | None:
        return self._split(token, node, first=True)

    def _split(self, token: _Token, node: NodePlan, *, first: bool) -> NodePlan | None:
        """An exclusive (``first``) or inclusive split; no flow to take is a model error."""
        flows = self._taken(node, first=first)
        if not flows:
            raise ModelError(
                f"robot {self.robot.name}: {node.node.kind} {node.node.describe()} has no "
                "outgoing flow whose condition holds and no default flow"
            )
        return self._follow(token, flows)

    def _run_parallel_gateway(self, token: _Token, node: NodePlan) -> NodePlan | None:
        if len(node.incoming) > 1 and not self._joined(token, node):
            return None
        return self._follow(token, list(node.outgoing))

    def _run_inclusive_gateway(self, token: _Token, node: NodePlan) -> NodePlan | None:
        if len(node.incoming) > 1:
            token.scope.joins.setdefault(node.id, []).append(token)
            self._inclusive.add(token.scope)
            return None
        return self._split(token, node, first=False)

    def _run_event_based_gateway(self, token: _Token, node: NodePlan) -> NodePlan | None:
        for flow in node.outgoing:
            target = flow.target
            if target.trigger is not None:
                token.waits.append(self.triggers.arm(target.trigger, self._waker(token, target)))
        return None

    def _joined(self, token: _Token, node: NodePlan) -> bool:
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

    def _recheck_joins(self) -> None:
        for scope in list(self._inclusive):
            for node_id, waiting in list(scope.joins.items()):
                node = scope.plan.nodes[node_id]
                if node.behaviour == "inclusiveGateway" and waiting and self._may_go(scope, node):
                    self._merge_inclusive(scope, node, waiting)
            if not any(scope.joins.values()):
                self._inclusive.discard(scope)

    def _may_go(self, scope: _Scope, node: NodePlan) -> bool:
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

    def _merge_inclusive(self, scope: _Scope, node: NodePlan, waiting: list[_Token]) -> None:
        survivor, *others = waiting
        scope.joins[node.id] = []
        for other in others:
            other.alive = False
            scope.tokens.discard(other)
        next_node = self._split(survivor, node, first=False)
        if next_node is not None:
            self._push(survivor, next_node)

    def _run_boundary(self, token: _Token, node: NodePlan) -> NodePlan | None:
        return self._follow(token, self._taken(node, first=False))

    def _run_event_subprocess(self, token: _Token, node: NodePlan) -> NodePlan | None:
        return None  # never entered by a sequence flow; _event_subprocess starts it

    # -- loops and multi-instance activities -----------------------------------------------------

    def _run_loop(self, token: _Token, node: NodePlan) -> NodePlan | None:
        """Run the activity's body once per instance (all at once when parallel), then leave
        by the activity's flows; the token waits at the activity meanwhile, with its boundary
        events armed, and cancelling it cancels the instances."""
        marker = node.loop.loop
        items = None if marker.kind == "standard" else self._loop_items(node)
        run = _Loop(token, node, items)
        if self._loop_finished(run, before=True):
            return self._follow(token, self._taken(node, first=False))
        self._arm_boundaries(token, node)
        token.waits.append(lambda: self._stop_instances(run))
        count = len(items) if marker.kind == "parallel" else 1
        for _ in range(count):
            self._start_instance(run)
        return None

    def _loop_items(self, node: NodePlan) -> list[Any]:
        """The items of a multi-instance activity: its collection's, or ``loopCardinality``
        times None."""
        looped = node.loop
        where = f"the multi-instance activity {node.node.describe()}"
        if looped.cardinality is not None:
            count = self._evaluate(looped.cardinality, where)
            if not isinstance(count, int | float) or count < 0 or count != int(count):
                raise ModelError(
                    f"robot {self.robot.name}: the loopCardinality of {where} is {count!r}, "
                    "not a whole number of instances"
                )
            return [None] * int(count)
        name = looped.loop.collection
        if name not in self.variables:
            raise ModelError(
                f"robot {self.robot.name}: {where} runs once per item of the variable "
                f"{name!r}, which is not set"
            )
        collection = self.variables[name]
        if isinstance(collection, Mapping):
            return list(collection.values())
        if isinstance(collection, str) or not isinstance(collection, Iterable):
            raise ModelError(
                f"robot {self.robot.name}: {where} runs once per item of the variable "
                f"{name!r}, which holds {type(collection).__name__} {collection!r}, no list"
            )
        return list(collection)

    def _start_instance(self, run: _Loop) -> None:
        index = run.next
        run.next += 1
        body = run.node.loop.body
        token = self._new_token(run.holder.scope, body)
        token.instance = run
        run.active[token] = index
        if run.items is not None:  # a multi-instance activity: each instance its own frame
            token.frame = _Frame(run.holder.frame, self._own_variables(run, index))

        def begin() -> None:
            if token.alive:
                self._enter_token(token)
                self.data.set(self._instance_variables(run, index))
                self._advance(token, body)

        self._call(begin)

    def _own_variables(self, run: _Loop, index: int) -> dict[str, Any]:
        """The variables an instance of a multi-instance activity has for itself."""
        marker = run.node.loop.loop
        own: dict[str, Any] = {"loopCounter": index}
        if marker.element:
            own[marker.element] = run.items[index]
        if marker.output_element:
            own[marker.output_element] = _ABSENT
        return own

    def _instance_variables(self, run: _Loop, index: int) -> dict[str, Any]:
        """What an instance finds in the variables as it starts (Camunda's names)."""
        marker = run.node.loop.loop
        values: dict[str, Any] = {"loopCounter": index}
        if run.items is not None:
            values["nrOfInstances"] = len(run.items)
            values["nrOfActiveInstances"] = len(run.active)
            values["nrOfCompletedInstances"] = run.completed
            if marker.element:
                values[marker.element] = run.items[index]
        return values

    def _instance_done(self, token: _Token) -> None:
        """One instance completed: collect its output, then start the next, wait for the
        others or leave the activity."""
        run = token.instance
        index = run.active.pop(token)
        run.completed += 1
        marker = run.node.loop.loop
        self._enter_token(token)  # its output item is in its own frame
        if marker.output_collection and run.items is not None:
            run.outputs[index] = self.variables.get(marker.output_element)
        if run.items is not None:
            self.data.set(
                {"nrOfCompletedInstances": run.completed, "nrOfActiveInstances": len(run.active)}
            )
        completion = self._loop_finished(run, before=False)  # may read the instance's item
        self._enter(run.holder.frame)
        if marker.output_collection and run.items is not None:
            # the outputs of the instances that completed, in instance order (as SpiffWorkflow)
            self.data.set({marker.output_collection: [run.outputs[i] for i in sorted(run.outputs)]})
        if completion:
            holder = run.holder
            self._disarm(holder)  # cancels the instances a completion condition cut short
            self._go_on(holder, run.node)
        elif marker.kind != "parallel":
            self._start_instance(run)

    def _loop_finished(self, run: _Loop, *, before: bool) -> bool:
        """Whether no more instance is to run: a standard loop's maximum reached or its
        condition false (before the first iteration only with ``testBefore``), every item
        done, or a multi-instance completion condition true."""
        looped = run.node.loop
        marker = looped.loop
        where = f"the loop of {run.node.node.describe()}"
        if marker.kind == "standard":
            if before and not marker.test_before:
                return False
            if marker.maximum is not None and run.completed >= marker.maximum:
                return True
            self.data.set({"loopCounter": run.completed})
            return looped.condition is not None and not self._condition(looped.condition, where)
        if run.completed >= len(run.items):
            return True
        if before or looped.condition is None:
            return False
        return self._condition(looped.condition, where)

    def _stop_instances(self, run: _Loop) -> None:
        for token in list(run.active):
            token.instance = None  # cancelled, not completed
            self._cancel(token)
        run.active.clear()

    #: how a node runs, by the behaviour the deployer gave it (``NodePlan.behaviour``)
    _BEHAVIOURS: ClassVar[dict[str, Behaviour]] = {
        "start": _run_start,
        "catch": _run_catch,
        "boundary": _run_boundary,
        "pass": _run_pass,
        "end": _run_end,
        "terminate": _run_terminate,
        "task": _run_task,
        "script": _run_script,
        "skill": _run_skill,
        "call": _run_call,
        "subprocess": _run_call,  # its content runs like a called process
        "event_subprocess": _run_event_subprocess,
        "loop": _run_loop,
        "exclusiveGateway": _run_exclusive_gateway,
        "parallelGateway": _run_parallel_gateway,
        "inclusiveGateway": _run_inclusive_gateway,
        "eventBasedGateway": _run_event_based_gateway,
    }

    # -- boundary events and event sub-processes -----------------------------------------------

    def _arm_boundaries(self, token: _Token, node: NodePlan) -> None:
        depth = token.scope.depth + 0.5  # inside the scope, around the activity
        for boundary in node.boundaries:
            if boundary.trigger.kind == "escalation":
                continue  # found when an escalation is thrown inside (see _escalate)
            repeat = not boundary.node.cancel_activity
            fire = self._boundary_fire(token, boundary)
            token.boundaries.append(
                self.triggers.arm(boundary.trigger, fire, repeat=repeat, depth=depth)
            )

    def _boundary_fire(
        self, token: _Token, boundary: NodePlan
    ) -> Callable[[Envelope | None], None]:
        generation = token.generation

        def fire(envelope: Envelope | None) -> None:
            if token.alive and token.generation == generation:
                self._boundary(token, boundary, envelope)

        return fire

    def _boundary(self, token: _Token, boundary: NodePlan, envelope: Envelope | None) -> None:
        if boundary.node.cancel_activity:
            scope = token.scope
            with self._interrupting():
                self._cancel(token)
            token = self._new_token(scope, boundary)
        else:
            token = self._new_token(token.scope, boundary)
        self._caught(token, boundary, envelope)

    def _arm_event_subprocess(self, scope: _Scope, esp: NodePlan) -> None:
        start = esp.child.triggered_starts[0]
        interrupting = start.node.interrupting
        if start.trigger.kind == "compensate":
            return  # it runs when its scope is compensated (see _compensate_one)
        if start.trigger.kind == "escalation":  # nothing to wait for outside the engine
            scope.armed[esp.id] = _nothing
            return

        def fire(envelope: Envelope | None) -> None:
            if not scope.ended and esp.id in scope.armed:
                self._event_subprocess(scope, esp, envelope, interrupting=interrupting)

        scope.armed[esp.id] = self.triggers.arm(
            start.trigger, fire, repeat=not interrupting, depth=scope.depth
        )

    def _event_subprocess(
        self,
        scope: _Scope,
        esp: NodePlan,
        envelope: Envelope | None,
        *,
        interrupting: bool,
        triggered: bool = True,
    ) -> None:
        if interrupting and esp.id in scope.armed:
            scope.armed.pop(esp.id)()  # an interrupting handler runs once per scope
        if esp is scope.plan.safe_state:
            scope.safe = True
        holder = self._new_token(scope, esp)
        if interrupting:
            with self._interrupting():
                for token in list(scope.tokens):
                    if token is not holder:
                        self._cancel(token)
        self._begin(holder, esp.label)
        child = self._open(esp.child, scope, holder)
        start = esp.child.triggered_starts[0]
        token = self._new_token(child, start)
        if triggered:
            self._caught(token, start, envelope)
        else:
            self._go_on(token, start)

    # -- compensation (BPMN 2.0 sections 10.6.5 and 13.5.5) ----------------------------------------

    def _compensable(self, token: _Token, node: NodePlan, child: _Scope | None = None) -> None:
        """Remember a completed activity that has something to compensate: a compensation
        handler, or (a sub-process) a compensation event sub-process or completed content."""
        scope = token.scope
        if child is not None and not child.done and child.plan.compensation_handler is None:
            child = None
        if child is None and node.id not in scope.plan.compensations:
            return
        scope.done.append(_Done(node, scope, token.frame, child))

    def _throw_compensation(self, token: _Token, node: NodePlan, then: Callable[[], Any]) -> bool:
        """Compensate the activity the event names, or every completed one of its scope (of
        the scope around, thrown in an event sub-process), the last completed first. True
        when the thrower goes on now; else ``then`` runs once the compensation is done."""
        self._tag.pair(node.throw.label)
        scope = token.scope
        if scope.holder is not None and scope.holder.node.behaviour == "event_subprocess":
            scope = scope.parent
        records = _take_done(scope, node.throw.topic)
        if not node.throw.wait or not records:
            self._compensate_all(records, _nothing)
            return True
        generation = token.generation

        def resume() -> None:
            if token.alive and token.generation == generation:
                self._enter_token(token)
                then()

        self._compensate_all(records, resume)
        return False

    def _compensate_all(self, records: list[_Done], then: Callable[[], Any]) -> None:
        """Compensate ``records`` one after the other, then call ``then``."""
        if not records:
            then()
            return
        first, rest = records[0], records[1:]
        self._compensate_one(first, lambda: self._compensate_all(rest, then))

    def _compensate_one(self, record: _Done, then: Callable[[], Any]) -> None:
        """Run one activity's compensation: its handler; for a sub-process without one, its
        compensation event sub-process, else its own completed activities in reverse."""
        handler = record.scope.plan.compensations.get(record.node.id)
        if handler is not None:
            place = self._compensation_scope(record.scope, record.frame, then)
            self._push(self._new_token(place, handler), handler)
            return
        child = record.child
        esp = child.plan.compensation_handler if child is not None else None
        if esp is None:
            self._compensate_all(_take_done(child, "") if child is not None else [], then)
            return
        place = self._compensation_scope(child, child.frame, then)
        place.done = child.done  # what a compensation throw inside the handler compensates
        holder = self._new_token(place, esp)
        self._begin(holder, esp.label)
        inner = self._open(esp.child, place, holder)
        start = esp.child.triggered_starts[0]
        self._caught(self._new_token(inner, start), start, None)

    def _compensation_scope(
        self, scope: _Scope, frame: _Frame | None, then: Callable[[], Any]
    ) -> _Scope:
        """A scope beside ``scope`` (its plan, its frame) for a compensation to run in;
        ``then`` runs when its last token is gone."""
        place = _Scope(scope.plan, scope, None)
        self._compensating.add(place)

        def closed() -> None:
            self._compensating.discard(place)
            then()

        place.frame, place.on_close = frame, closed
        return place

    # -- activity tags -----------------------------------------------------------------------------

    def _begin(self, token: _Token, label: str) -> None:
        """``token``'s activity starts: tagged, and remembered until it ends."""
        self._tag(label, START)
        self._instances += 1
        self._running[token] = (label, self._instances)
        if self.activity_observer is not None:
            self.activity_observer(self.robot.name, self._instances, label, "start")

    def _end(self, token: _Token, lifecycle: str) -> None:
        """``token``'s activity, if one runs, ends: ``complete``, or ``ate_abort`` when it was
        interrupted or cancelled."""
        running = self._running.pop(token, None)
        if running is None:
            return
        label, number = running
        self._tag(label, lifecycle)
        if self.activity_observer is not None:
            how = "completed" if lifecycle == COMPLETE else self._ending
            self.activity_observer(self.robot.name, number, label, how)

    @contextlib.contextmanager
    def _interrupting(self):
        """The activities cancelled meanwhile were interrupted (an interrupting boundary event
        or event sub-process), not merely cancelled."""
        before, self._ending = self._ending, "interrupted"
        try:
            yield
        finally:
            self._ending = before

    # -- errors ------------------------------------------------------------------------------------

    def _throw_error(self, token: _Token, name: str) -> None:
        """Hand a thrown BPMN error to the nearest catcher: the activity's own boundary
        events, then the event sub-processes of each enclosing scope and the boundary events
        of the activity holding it; nobody catching it ends the instance."""
        catcher = self._boundary_catcher(_outer(token), "error", name)
        if catcher is not None:
            self._boundary(_outer(token), catcher, None)
            return
        if not self._catch_above(token, "error", name):
            self._uncaught(token, name)

    def _catch_above(self, token: _Token, kind: str, name: str) -> bool:
        """Hand an error or escalation thrown at ``token`` to the event sub-processes of each
        enclosing scope and the boundary events of the activity holding it, innermost first;
        False when nobody catches it."""
        scope: _Scope | None = token.scope
        while scope is not None:
            esp = self._esp_catcher(scope, kind, name)
            if esp is not None:
                interrupting = kind == "error" or esp.child.triggered_starts[0].node.interrupting
                self._event_subprocess(scope, esp, None, interrupting=interrupting)
                return True
            if scope.holder is not None:
                holder = _outer(scope.holder)
                catcher = self._boundary_catcher(holder, kind, name)
                if catcher is not None:
                    self._boundary(holder, catcher, None)
                    return True
            scope = scope.parent
        return False

    def _escalate(self, token: _Token, node: NodePlan) -> bool:
        """Throw an escalation (tagged as the throwing event); True when the thrower goes on
        (nobody caught it, or a non-interrupting catcher did)."""
        self._tag.pair(node.throw.label)
        self._catch_above(token, "escalation", node.throw.topic)
        return token.alive

    def _boundary_catcher(self, token: _Token, kind: str, name: str) -> NodePlan | None:
        for boundary in token.node.boundaries:
            trigger = boundary.trigger
            if trigger.kind == kind and trigger.topic in ("", name):
                return boundary
        return None

    def _esp_catcher(self, scope: _Scope, kind: str, name: str) -> NodePlan | None:
        for esp in scope.plan.event_subprocesses:
            trigger = esp.child.triggered_starts[0].trigger
            if esp.id in scope.armed and trigger.kind == kind and trigger.topic in ("", name):
                return esp
        return None

    def _uncaught(self, token: _Token, name: str) -> None:
        self._fail(
            token,
            f"robot {self.robot.name}: error {name!r} thrown at {token.node.node.describe()} "
            "was not caught; the process instance ended",
        )

    def _fail(self, token: _Token, sentence: str) -> None:
        """End ``token``'s process instance as failed, saying why."""
        root = token.scope
        while root.parent is not None:
            root = root.parent
        self.failures.append(sentence)
        root.failed = True
        self._kill(root, safe=False)

    def _script_limit(self, token: _Token, node: NodePlan, what: str) -> None:
        """A script ran out of time or memory: a model error, not a BPMN error (no boundary
        event may catch it), that ends the robot's instance."""
        self._fail(
            token,
            f"robot {self.robot.name}: script task {node.node.describe()} {what}; the process "
            "instance ended (a model error: no boundary event catches it)",
        )

    # -- messages ------------------------------------------------------------------------------

    def _received(self, node: NodePlan, envelope: Envelope | None) -> dict[str, Any]:
        """Tag a fired catching event; a message's data goes to the variables."""
        trigger = node.trigger
        if envelope is None or trigger.kind != "signal":
            self._tag.pair(trigger.label)
            return {}
        payload = payload_text(envelope.data)
        self._tag.pair(trigger.label, envelope.msg_id, "receive", payload)
        return self.data.received(trigger.topic, envelope.data)

    def _publish(self, node: NodePlan) -> None:
        throw = node.throw
        data = self.data.payload(node)
        msg_id = self._tag.new_msg_id()
        payload = payload_text(data)
        self._tag(throw.label, "start", msg_id, "send", payload)
        self.bus.publish(
            throw.topic,
            data,
            msgtype=throw.msgtype,
            sender=self.robot.name,
            msg_id=msg_id,
            qos=throw.qos,
        )
        self._tag(throw.label, "complete", msg_id, "send", payload)

    def _changed(self, names: Iterable[str]) -> None:
        self.triggers.changed(names)


def _nothing() -> None:
    return None


def _take_done(scope: _Scope, activity: str) -> list[_Done]:
    """The completed activities of ``scope`` to compensate (``activity``'s instances only,
    when named), the last completed first; they are compensated once, so they leave it."""
    taken = [d for d in scope.done if not activity or d.node.id == activity]
    scope.done = [d for d in scope.done if d not in taken]
    return taken[::-1]


def _outer(token: _Token) -> _Token:
    """The token whose activity's boundary events catch for ``token``: an instance of a loop
    or multi-instance activity is caught around the whole activity."""
    return token.instance.holder if token.instance is not None else token
