"""Deploying a process: the model compiled into what the engine runs, or refused.

:func:`deploy` checks every element once -- scripts and conditions compiled, signal topics and
timers resolved, call activities bound to a skill or a process -- and refuses the process with
one :class:`~robotale.errors.ModelError` naming every element the engine cannot run.
:func:`problems` lists the same without raising, for ``robotale fame check``, and
:func:`findings` as :class:`~robotale.fame_runtime.model.Problem` (file, line, element).
"""

from __future__ import annotations

import re
from collections.abc import Collection
from dataclasses import dataclass, field
from typing import Literal, TypeVar

from robotale.errors import ModelError
from robotale.fame_runtime.expressions import Compiled, compile_condition, compile_script
from robotale.fame_runtime.kinds import (
    ACTIVITIES,
    EVENTS,
    GATEWAYS,
    HANDLER_TRIGGERS,
    MESSAGE_TASKS,
    EventKind,
    Kind,
    LoopKind,
    Run,
)
from robotale.fame_runtime.labels import (
    catches,
    element_label,
    error_name,
    escalation_name,
    message_name,
    message_topic,
    signal_topic,
)
from robotale.fame_runtime.library import Library, resolve_call
from robotale.fame_runtime.model import (
    JAVASCRIPT,
    DataObject,
    Definitions,
    Loop,
    Node,
    Problem,
    Process,
    RosMessage,
    Scope,
)
from robotale.fame_runtime.qos import DEFAULT_QOS, QoS
from robotale.fame_runtime.splitter import namespace
from robotale.fame_runtime.timers import TimerSpec

EMPTY_MSGTYPE = "std_msgs/msg/Empty"
_T = TypeVar("_T")

#: what a robot runs instead of a task kind it does not run
_TASKS = "a task, script task, send or receive task, or a call activity bound to a skill"

#: elements of BPMN the engine does not run, why, and what it would run instead
OUTSIDE = {
    Kind.USER_TASK: f"needs a person (robotale runs {_TASKS})",
    Kind.MANUAL_TASK: f"needs a person (robotale runs {_TASKS})",
    Kind.SERVICE_TASK: "is a service call (use a call activity bound to a skill)",
    Kind.BUSINESS_RULE_TASK: f"needs a rule engine (robotale runs {_TASKS})",
    Kind.TRANSACTION: "is a transaction (robotale runs a plain sub-process)",
    Kind.AD_HOC_SUB_PROCESS: "is an ad-hoc sub-process (robotale runs a plain sub-process)",
    Kind.COMPLEX_GATEWAY: (
        "is a complex gateway (robotale runs exclusive, parallel, inclusive and event-based "
        "gateways)"
    ),
    Kind.IMPLICIT_THROW_EVENT: (
        "is an implicit throw event (robotale runs intermediate throw events)"
    ),
}

_ROLES = {
    "start": "process start event",
    "event_start": "event sub-process start event",
    "sub_start": "sub-process start event",
    "called_start": "called process start event",
    Kind.INTERMEDIATE_CATCH_EVENT: "catching intermediate event",
    Kind.INTERMEDIATE_THROW_EVENT: "throwing intermediate event",
    Kind.END_EVENT: "end event",
    Kind.BOUNDARY_EVENT: "boundary event",
}

#: the event kinds each kind of event may have ("none" = no event definition)
ALLOWED: dict[str, frozenset[EventKind] | set[EventKind]] = {
    "start": {
        EventKind.NONE,
        EventKind.SIGNAL,
        EventKind.TIMER,
        EventKind.CONDITIONAL,
        EventKind.MESSAGE,
    },
    "event_start": HANDLER_TRIGGERS,
    "sub_start": {EventKind.NONE},
    "called_start": {EventKind.NONE},
    Kind.INTERMEDIATE_CATCH_EVENT: {
        EventKind.SIGNAL,
        EventKind.TIMER,
        EventKind.CONDITIONAL,
        EventKind.MESSAGE,
    },
    Kind.INTERMEDIATE_THROW_EVENT: {
        EventKind.NONE,
        EventKind.SIGNAL,
        EventKind.MESSAGE,
        EventKind.ESCALATION,
        EventKind.COMPENSATE,
    },
    Kind.END_EVENT: {
        EventKind.NONE,
        EventKind.TERMINATE,
        EventKind.SIGNAL,
        EventKind.ERROR,
        EventKind.MESSAGE,
        EventKind.ESCALATION,
        EventKind.COMPENSATE,
    },
    Kind.BOUNDARY_EVENT: HANDLER_TRIGGERS,
}
_SAFE_STATE = re.compile(r"safe[\s_-]*state", re.IGNORECASE)


@dataclass(slots=True, eq=False)
class Trigger:
    """What a catching event waits for (a message is a signal on its receiver's topic)."""

    kind: EventKind  # signal | timer | conditional | error | escalation | compensate
    label: str  # the activity its tags carry
    topic: str = ""  # signal: /name; error: the robot-relative name ("" catches any error)
    msgtype: str = ""
    qos: QoS = DEFAULT_QOS
    timer: TimerSpec | None = None
    condition: Compiled | None = None


@dataclass(slots=True, eq=False)
class Throw:
    """What a throwing event publishes or raises."""

    kind: EventKind  # signal | message | error | escalation | compensate
    label: str
    topic: str  # compensate: the activity to compensate ("" every completed one)
    msgtype: str = EMPTY_MSGTYPE
    payload: dict[str, str] | str | None = None
    qos: QoS = DEFAULT_QOS
    wait: bool = True  # compensate: the thrower waits until the compensation is done


@dataclass(slots=True, eq=False)
class FlowPlan:
    id: str
    target: NodePlan
    condition: Compiled | None = None


@dataclass(slots=True, eq=False)
class NodePlan:
    node: Node
    behaviour: Run | Literal[""]  # how the engine runs it (behaviours.BEHAVIOURS); "": refused
    label: str
    scope: ScopePlan
    outgoing: list[FlowPlan] = field(default_factory=list)
    default: FlowPlan | None = None
    incoming: list[str] = field(default_factory=list)  # sequence flow ids
    boundaries: list[NodePlan] = field(default_factory=list)
    trigger: Trigger | None = None
    throw: Throw | None = None
    script: Compiled | None = None
    skill: str = ""
    child: ScopePlan | None = None  # sub-process content or called process
    data_inputs: list[DataObject] = field(default_factory=list)
    data_outputs: list[DataObject] = field(default_factory=list)
    reach: frozenset[str] | None = None  # see reachable_flows
    loop: LoopPlan | None = None  # behaviour "loop": how often ``loop.body`` runs

    @property
    def id(self) -> str:
        return self.node.id

    # What the deployer gives every node of a kind, for the readers that know the kind: a
    # node plan of another kind has none (an AttributeError naming the field).

    @property
    def content(self) -> ScopePlan:
        """A call activity's or sub-process's ``child``."""
        return _given(self, "child", self.child)

    @property
    def looping(self) -> LoopPlan:
        """A loop node's ``loop``."""
        return _given(self, "loop", self.loop)

    @property
    def caught(self) -> Trigger:
        """A catching event's (or receive task's) ``trigger``."""
        return _given(self, "trigger", self.trigger)

    @property
    def thrown(self) -> Throw:
        """A throwing event's (or send task's) ``throw``."""
        return _given(self, "throw", self.throw)


@dataclass(slots=True, eq=False)
class LoopPlan:
    """A loop or multi-instance activity: its marker, the conditions compiled, and the
    activity without its marker (``body``, no outgoing flows: one instance of it)."""

    loop: Loop
    body: NodePlan
    cardinality: Compiled | None = None
    condition: Compiled | None = None


@dataclass(slots=True, eq=False)
class ScopePlan:
    """A process, a called process or a sub-process, ready to run."""

    process: Process
    nodes: dict[str, NodePlan] = field(default_factory=dict)
    starts: list[NodePlan] = field(default_factory=list)  # none start events
    triggered_starts: list[NodePlan] = field(default_factory=list)  # top level only
    event_subprocesses: list[NodePlan] = field(default_factory=list)
    data_objects: list[DataObject] = field(default_factory=list)  # initialised on entry
    safe_state: NodePlan | None = None
    #: activity id -> the compensation handler its compensation boundary event names
    compensations: dict[str, NodePlan] = field(default_factory=dict)
    #: the event sub-process whose start is a compensation event (compensates this scope)
    compensation_handler: NodePlan | None = None


def deploy(
    process: Process,
    *,
    skills: Collection[str] = (),
    library: Library | None = None,
) -> ScopePlan:
    """The process ready to run, or a ModelError naming every element the engine cannot run."""
    planner = _Planner(skills, library)
    plan = planner.process(process, top=True)
    if planner.found:
        file = f"{process.file}: " if process.file else ""
        raise ModelError(
            f"{file}the engine cannot run process {process.describe()}: "
            + "; ".join(f"{p.sentence} (line {p.line})" for p in planner.found),
            problems=_placed(process, planner.found),
        )
    return plan


def problems(
    process: Process, *, skills: Collection[str] = (), library: Library | None = None
) -> list[str]:
    """What :func:`deploy` would refuse in ``process``, one phrase per element."""
    return [p.sentence for p in findings(process, skills=skills, library=library)]


def findings(
    process: Process, *, skills: Collection[str] = (), library: Library | None = None
) -> list[Problem]:
    """What :func:`deploy` would refuse in ``process``, with file, line and element id."""
    planner = _Planner(skills, library)
    planner.process(process, top=True)
    return _placed(process, planner.found)


def speaks_javascript(plan: ScopePlan) -> bool:
    """Whether a script or condition of ``plan`` (its sub-processes and the processes it
    calls included) is JavaScript: the process is written in FAME's dialect."""
    seen: set[int] = set()

    def scope(current: ScopePlan) -> bool:
        if id(current) in seen:
            return False
        seen.add(id(current))
        nodes = [*current.nodes.values(), *current.event_subprocesses]
        return any(node_speaks(node) for node in nodes)

    def node_speaks(node: NodePlan) -> bool:
        compiled = [node.script, *(f.condition for f in node.outgoing)]
        if node.trigger is not None:
            compiled.append(node.trigger.condition)
        if any(c is not None and c.language == JAVASCRIPT for c in compiled):
            return True
        return node.child is not None and scope(node.child)

    return scope(plan)


def reachable_flows(node: NodePlan) -> frozenset[str]:
    """The sequence flows a token at ``node`` may still take (boundary events included);
    an inclusive join waits while some token can still reach one of its incoming flows."""
    if node.reach is None:
        seen: set[str] = set()
        stack = [node]
        visited: set[int] = set()
        while stack:
            current = stack.pop()
            if id(current) in visited:
                continue
            visited.add(id(current))
            for flow in current.outgoing:
                seen.add(flow.id)
                stack.append(flow.target)
            stack.extend(current.boundaries)
        node.reach = frozenset(seen)
    return node.reach


class _Planner:
    def __init__(self, skills: Collection[str], library: Library | None) -> None:
        self.skills = skills
        self.library = library
        self.found: list[Problem] = []
        self.file = ""  # the file of the process being planned (a called one has its own)
        self.called: dict[int, ScopePlan] = {}
        self.where = ""  # which called process the planner is in, for messages
        self.definitions: Definitions | None = None  # the top process's file (messages)
        self.pool = ""  # the namespace of the top process's pool (its messages' topics)

    def refuse(self, node: Node, reason: str) -> None:
        self.found.append(
            Problem(
                self.file, node.line, node.id, f"{node.kind} {node.describe()}{self.where} {reason}"
            )
        )

    def problem(self, line: int, element: str, sentence: str) -> None:
        self.found.append(Problem(self.file, line, element, sentence))

    def process(self, process: Process, *, top: bool = False) -> ScopePlan:
        if id(process) in self.called:  # recursive calls share one plan
            return self.called[id(process)]
        plan = ScopePlan(process, data_objects=list(process.data_objects.values()))
        self.called[id(process)] = plan
        if top:
            self.definitions = process.definitions
            self.pool = _pool_namespace(process.definitions, process.id)
        outer, outer_file = self.where, self.file
        self.file = str(process.file or "")
        if not top:
            file = f" ({process.file.name})" if process.file else ""
            self.where = f" of called process {process.describe()}{file}"
        self.scope(process, plan, top=top)
        self.where = outer
        if not plan.starts and not plan.triggered_starts:
            plan.starts = _implicit_starts(plan)
        if top and not plan.starts and not plan.triggered_starts:
            self.problem(
                process.line,
                process.id,
                f"process {process.describe()} has no start event and nothing else to start "
                "(add a bpmn:startEvent)",
            )
        self.file = outer_file
        return plan

    def scope(
        self, scope: Scope, plan: ScopePlan, *, top: bool = False, event: bool = False
    ) -> None:
        for node in scope.nodes.values():
            plan.nodes[node.id] = NodePlan(node, "", "", plan)
        for node_plan in plan.nodes.values():
            self.node(node_plan, plan, top=top, event=event)
        self.flows(scope, plan)
        for node_plan in plan.nodes.values():
            self.gateway(node_plan)
            self.compensation(node_plan, plan)
        plan.safe_state = next(
            (n for n in plan.event_subprocesses if _SAFE_STATE.search(n.node.name)), None
        )

    def flows(self, scope: Scope, plan: ScopePlan) -> None:
        for flow in scope.flows.values():
            source, target = plan.nodes[flow.source], plan.nodes[flow.target]
            condition = None
            if flow.condition is not None:
                try:
                    condition = compile_condition(flow.condition)
                except ValueError as error:
                    self.problem(
                        flow.line,
                        flow.id,
                        f"sequence flow {flow.id}{self.where} has a condition the engine "
                        f"cannot run: {error}",
                    )
            flow_plan = FlowPlan(flow.id, target, condition)
            source.outgoing.append(flow_plan)
            target.incoming.append(flow.id)
            if source.node.default_flow == flow.id:
                source.default = flow_plan

    def gateway(self, plan: NodePlan) -> None:
        node = plan.node
        if node.kind in GATEWAYS and not plan.outgoing:
            self.refuse(node, "has no outgoing sequence flow (give it at least one)")
        if node.kind == Kind.EVENT_BASED_GATEWAY:
            for flow in plan.outgoing:
                target = flow.target.node
                if target.kind != Kind.INTERMEDIATE_CATCH_EVENT:
                    self.refuse(
                        node,
                        f"leads to {target.describe()}, which is no catching event (an "
                        "event-based gateway leads to intermediate catch events)",
                    )
        if node.kind == Kind.START_EVENT and plan.incoming:
            self.refuse(node, "has incoming sequence flows (a start event has none)")
        if node.kind == Kind.END_EVENT and plan.outgoing:
            self.refuse(node, "has outgoing sequence flows (an end event has none)")

    def compensation(self, plan: NodePlan, scope: ScopePlan) -> None:
        """A compensation boundary event binds its handler to its activity; the handler runs
        only to compensate, never by a sequence flow (BPMN 2.0 section 10.6.5)."""
        node = plan.node
        if node.for_compensation and (plan.incoming or plan.outgoing):
            self.refuse(
                node,
                "is a compensation handler (isForCompensation) with sequence flows: it runs "
                "only when its activity is compensated (remove its incoming and outgoing flows)",
            )
        if node.kind != Kind.BOUNDARY_EVENT or node.event_kind != EventKind.COMPENSATE:
            return
        handler = scope.nodes.get(node.compensation_handler)
        if handler is not None and node.attached_to in scope.nodes:
            scope.compensations[node.attached_to] = handler
        if plan.outgoing:
            self.refuse(
                node,
                "is a compensation boundary event with outgoing sequence flows (its handler is "
                "joined by an association, not a flow)",
            )

    def node(self, plan: NodePlan, scope: ScopePlan, *, top: bool, event: bool) -> None:
        node = plan.node
        plan.label = element_label(node)
        plan.data_inputs = [scope.process.data_objects[r] for r in node.data_inputs]
        plan.data_outputs = [scope.process.data_objects[r] for r in node.data_outputs]
        for quirk in node.quirks:
            self.refuse(node, quirk)
        if node.kind in OUTSIDE:
            self.refuse(node, OUTSIDE[node.kind])
            return
        if len(node.events) > 1:
            self.refuse(node, "has several event definitions (robotale runs events with one)")
            return
        if node.kind in EVENTS:
            self.event(plan, scope, top=top, event=event)
        else:
            self.activity(plan, scope)
        if node.loop is not None:
            self.looped(plan, node.loop)

    def looped(self, plan: NodePlan, loop: Loop) -> None:
        """The activity becomes a loop around a copy of itself (its body): the loop owns the
        outgoing flows and the boundary events, the body runs once per instance."""
        body = NodePlan(
            plan.node,
            plan.behaviour,
            plan.label,
            plan.scope,
            trigger=plan.trigger,
            throw=plan.throw,
            script=plan.script,
            skill=plan.skill,
            child=plan.child,
            data_inputs=plan.data_inputs,
            data_outputs=plan.data_outputs,
        )
        looped = LoopPlan(loop, body)
        for name in ("cardinality", "condition"):
            expression = getattr(loop, name)
            if expression is None:
                continue
            try:
                setattr(looped, name, compile_condition(expression))
            except ValueError as error:
                self.refuse(plan.node, f"has a loop {name} the engine cannot run: {error}")
        if loop.kind == LoopKind.STANDARD and loop.condition is None and loop.maximum is None:
            self.refuse(
                plan.node,
                "has a standard loop without loopCondition or loopMaximum (give one, e.g. "
                'loopMaximum="5")',
            )
        if loop.kind != LoopKind.STANDARD and loop.cardinality is None and not loop.collection:
            self.refuse(
                plan.node,
                "has a multi-instance marker with neither a loopCardinality nor a collection "
                "(loopDataInputRef or camunda:collection), so robotale cannot tell how many "
                "instances to run: give one, e.g. <bpmn:loopCardinality>3</bpmn:loopCardinality>",
            )
        plan.behaviour, plan.loop = Run.LOOP, looped

    def activity(self, plan: NodePlan, scope: ScopePlan) -> None:
        node = plan.node
        if node.kind in GATEWAYS:
            plan.behaviour = Run(node.kind)
        elif node.kind == Kind.TASK:
            plan.behaviour = Run.TASK
        elif node.kind == Kind.SCRIPT_TASK:
            plan.behaviour = Run.SCRIPT
            try:
                plan.script = compile_script(node.script) if node.script else None
            except ValueError as error:
                self.refuse(node, f"has a script that cannot run: {error}")
        elif node.kind in MESSAGE_TASKS:
            self.message_task(plan)
        elif node.kind == Kind.CALL_ACTIVITY:
            self.call(plan)
        elif node.kind == Kind.SUB_PROCESS:
            self.subprocess(plan, scope)

    def message_task(self, plan: NodePlan) -> None:
        """A send task publishes like a message throw event, a receive task waits like a
        message catch event; both are tagged by their own name."""
        if plan.node.kind == Kind.SEND_TASK:
            plan.behaviour = Run.PASS
            plan.throw = self.message_throw(plan)
        else:
            plan.behaviour = Run.CATCH
            plan.trigger = self.trigger(plan)

    def message_throw(self, plan: NodePlan) -> Throw | None:
        """A message goes to the pool its message flow leads to, on that pool's topic."""
        node = plan.node
        targets = _message_targets(self.definitions, node.id)
        if len(targets) != 1:
            how = "no message flow leads" if not targets else f"{len(targets)} message flows lead"
            self.refuse(
                node,
                f"sends message {message_name(node) or '(unnamed)'} but {how} from it to "
                "another pool (draw exactly one message flow to the receiver)",
            )
            return None
        topic = message_topic(targets[0], node)
        if not topic:
            self.refuse(node, self.no_message(node))
        message = node.message or RosMessage()
        msgtype = message.msgtype or EMPTY_MSGTYPE
        return Throw(EventKind.MESSAGE, plan.label, topic, msgtype, message.payload, message.qos)

    def no_message(self, node: Node) -> str:
        """Why a message event or task has no topic: a messageRef to nothing, or no name."""
        ref = node.event.ref if node.event else ""
        declared = self.definitions.messages if self.definitions else {}
        if ref and ref not in declared:
            known = ", ".join(sorted(declared)) or "none"
            return (
                f"refers to message {ref}, which the file does not declare (messages: {known}; "
                f'declare <bpmn:message id="{ref}" name="..."/> or name the element)'
            )
        if ref:
            return f"refers to message {ref}, which has no name (give it or the element one)"
        return "names no message (give the element a name or a messageRef to a named message)"

    def call(self, plan: NodePlan) -> None:
        node = plan.node
        name = node.called_element
        if name and name in self.skills:
            plan.behaviour, plan.skill = Run.SKILL, name
            return
        process = node.embedded_process or resolve_call(name, plan.scope.process, self.library)
        definitions = plan.scope.process.definitions
        global_kind = definitions.global_tasks.get(name) if definitions else None
        if process is None and global_kind:
            self.refuse(
                node,
                f"calls the global task {name} (a bpmn:{global_kind}), which robotale does not "
                "run (call a process of the file, a building block or a skill)",
            )
            return
        if process is None:
            where = "no skill, no process of the file" + (
                f" and no building block in {self.library.folder}" if self.library else ""
            )
            what = (
                f"calls {name!r}, which is {where} (name one of those)"
                if name
                else "calls nothing (give it a calledElement naming a skill or a process)"
            )
            self.refuse(node, what)
            return
        plan.behaviour = Run.CALL
        plan.child = self.process(process)

    def subprocess(self, plan: NodePlan, scope: ScopePlan) -> None:
        node = plan.node
        child = ScopePlan(scope.process)
        plan.child = child
        if node.triggered_by_event:
            plan.behaviour = Run.EVENT_SUBPROCESS
            scope.event_subprocesses.append(plan)
        else:
            plan.behaviour = Run.SUBPROCESS
        self.scope(node.scope or Scope(), child, event=node.triggered_by_event)
        if node.triggered_by_event and len(child.triggered_starts) != 1:
            found = len(child.triggered_starts) or "no"
            self.refuse(
                node,
                f"is an event sub-process with {found} start events with a trigger: it needs "
                "exactly one (a signal, timer, conditional, error, message, escalation or "
                "compensation start event)",
            )
        elif (
            node.triggered_by_event
            and child.triggered_starts[0].node.event_kind == EventKind.COMPENSATE
        ):
            scope.compensation_handler = plan
        if not node.triggered_by_event and len(child.starts) > 1:
            self.refuse(
                node,
                f"is a sub-process with {len(child.starts)} none start events: it needs one "
                "(or none: then every element without an incoming flow starts)",
            )
        if not node.triggered_by_event and not child.starts:
            child.starts = _implicit_starts(child)  # none (an empty sub-process): it completes

    def event(self, plan: NodePlan, scope: ScopePlan, *, top: bool, event: bool) -> None:
        node = plan.node
        role: str = node.kind
        if node.kind == Kind.START_EVENT:
            role = "start" if top else ("event_start" if event else "sub_start")
            if role == "sub_start" and self.called.get(id(scope.process)) is scope:
                role = "called_start"  # the called process itself, not a sub-process of it
        if node.event_kind not in ALLOWED[role]:
            runs = ", ".join(sorted(ALLOWED[role]))
            self.refuse(
                node,
                f"is a {node.event_kind} {_ROLES[role]}, which the engine does not run (it runs "
                f"a {_ROLES[role]} of these kinds: {runs})",
            )
            return
        if catches(node):
            self.catching(plan, scope)
        else:
            self.throwing(plan)

    def catching(self, plan: NodePlan, scope: ScopePlan) -> None:
        node = plan.node
        if node.kind == Kind.BOUNDARY_EVENT and node.event_kind == EventKind.COMPENSATE:
            plan.behaviour = Run.BOUNDARY  # never armed: compensation runs its handler instead
            return
        if node.kind == Kind.BOUNDARY_EVENT:
            plan.behaviour = Run.BOUNDARY
            host = scope.nodes.get(node.attached_to)
            if host is None or host.node.kind not in ACTIVITIES:
                self.refuse(node, "is attached to something that is no activity (attach it to one)")
            else:
                host.boundaries.append(plan)
            if node.event_kind == EventKind.ERROR and not node.cancel_activity:
                self.refuse(node, "is a non-interrupting error event (errors always interrupt)")
        else:
            plan.behaviour = Run.START if node.kind == Kind.START_EVENT else Run.CATCH
        if node.kind == Kind.START_EVENT and node.event_kind == EventKind.NONE:
            scope.starts.append(plan)
            return
        if node.kind == Kind.START_EVENT:
            scope.triggered_starts.append(plan)
        plan.trigger = self.trigger(plan)

    def trigger(self, plan: NodePlan) -> Trigger | None:
        node = plan.node
        kind = node.event_kind
        message = node.message or RosMessage()
        if kind == EventKind.SIGNAL:
            topic = signal_topic(node)
            if not topic:
                self.refuse(node, "names no signal (give the event or its signal a name)")
            return Trigger(EventKind.SIGNAL, plan.label, topic, message.msgtype, message.qos)
        if kind == EventKind.ERROR:
            name = error_name(node)
            return Trigger(EventKind.ERROR, plan.label, name, EMPTY_MSGTYPE, message.qos)
        if kind == EventKind.MESSAGE:
            topic = message_topic(self.pool, node)
            if not topic:
                self.refuse(node, self.no_message(node))
            return Trigger(EventKind.SIGNAL, plan.label, topic, message.msgtype, message.qos)
        if kind == EventKind.ESCALATION:
            return Trigger(EventKind.ESCALATION, plan.label, escalation_name(node))
        if kind == EventKind.TIMER:
            timer = node.event.timer if node.event else None
            if timer is None:
                self.refuse(
                    node,
                    "is a timer without a date, duration or cycle (give a timeDate, "
                    "timeDuration or timeCycle with a value, e.g. PT10S)",
                )
            return Trigger(EventKind.TIMER, plan.label, timer=timer)
        if kind == EventKind.COMPENSATE:  # an event sub-process's start: run by compensation only
            return Trigger(EventKind.COMPENSATE, plan.label)
        return self.conditional(plan)

    def conditional(self, plan: NodePlan) -> Trigger | None:
        node = plan.node
        expression = node.event.condition if node.event else None
        if expression is None:
            self.refuse(
                node,
                "is a conditional event without a condition (give its "
                "conditionalEventDefinition a bpmn:condition)",
            )
            return None
        try:
            return Trigger(
                EventKind.CONDITIONAL, plan.label, condition=compile_condition(expression)
            )
        except ValueError as error:
            self.refuse(node, f"has a condition the engine cannot run: {error}")
            return None

    def throwing(self, plan: NodePlan) -> None:
        node = plan.node
        kind = node.event_kind
        if node.kind == Kind.END_EVENT:
            plan.behaviour = Run.TERMINATE if kind == EventKind.TERMINATE else Run.END
        else:
            plan.behaviour = Run.PASS
        message = node.message or RosMessage()
        if kind == EventKind.SIGNAL:
            topic = signal_topic(node)
            if not topic:
                self.refuse(node, "names no signal (give the event or its signal a name)")
            msgtype = message.msgtype or EMPTY_MSGTYPE
            plan.throw = Throw(
                EventKind.SIGNAL, plan.label, topic, msgtype, message.payload, message.qos
            )
        elif kind == EventKind.ERROR:
            plan.throw = Throw(EventKind.ERROR, plan.label, error_name(node))
        elif kind == EventKind.ESCALATION:
            plan.throw = Throw(EventKind.ESCALATION, plan.label, escalation_name(node))
        elif kind == EventKind.MESSAGE:
            plan.throw = self.message_throw(plan)
        elif kind == EventKind.COMPENSATE:
            plan.throw = self.compensation_throw(plan)

    def compensation_throw(self, plan: NodePlan) -> Throw:
        """A compensation throw names one activity (``activityRef``) or every completed one
        of its scope; the activity must be in the process."""
        node = plan.node
        event = node.event
        ref = event.ref if event else ""
        activities = {n.id for n in plan.scope.process.walk() if n.kind not in EVENTS}
        if ref and ref not in activities:
            self.refuse(
                node,
                f"compensates activity {ref}, which is no activity of process "
                f"{plan.scope.process.describe()} (name an activity beside the event, or none "
                "to compensate every completed one)",
            )
        return Throw(EventKind.COMPENSATE, plan.label, ref, wait=event.wait if event else True)


def _given(plan: NodePlan, name: str, value: _T | None) -> _T:
    if value is None:
        raise AttributeError(f"{plan.node.kind} {plan.node.describe()} has no {name}")
    return value


def _placed(process: Process, found: list[Problem]) -> list[Problem]:
    """``found`` with their elements' columns, where the process's file has them."""
    definitions = process.definitions
    return [definitions.placed(p) for p in found] if definitions is not None else found


def _implicit_starts(plan: ScopePlan) -> list[NodePlan]:
    """Where a process or sub-process without start events begins (BPMN 2.0 10.5.2): at
    every activity, gateway and intermediate event without an incoming sequence flow (not a
    boundary event, an event sub-process or a compensation handler)."""
    return [
        node
        for node in plan.nodes.values()
        if not node.incoming
        and node.node.kind not in (Kind.BOUNDARY_EVENT, Kind.START_EVENT)
        and node.behaviour != Run.EVENT_SUBPROCESS
        and not node.node.for_compensation
    ]


def _pool_namespace(definitions: Definitions | None, process_id: str) -> str:
    """The namespace of the pool holding ``process_id`` (its process id without pools)."""
    for participant in definitions.participants if definitions else ():
        if participant.process_ref == process_id:
            return namespace(participant.name)
    return namespace(process_id)


def _message_targets(definitions: Definitions | None, source: str) -> list[str]:
    """The namespaces of the pools the message flows from ``source`` lead to."""
    if definitions is None:
        return []
    pools = {p.id: p for p in definitions.participants}
    owner = {n.id: p.id for p in definitions.processes.values() for n in p.walk()}
    targets = []
    for _, flow_source, target in definitions.message_flows:
        if flow_source != source:
            continue
        pool = pools.get(target) or next(
            (p for p in pools.values() if p.process_ref == owner.get(target)), None
        )
        if pool is not None:
            targets.append(namespace(pool.name))
    return targets
