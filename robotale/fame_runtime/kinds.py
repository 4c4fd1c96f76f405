"""The vocabulary of BPMN element kinds robotale reads, runs, checks and discovers: the one
place that spells them.

Each kind is a :class:`enum.StrEnum` member whose value is the name BPMN 2.0's XML gives it
(``startEvent``, ``exclusiveGateway``, ``timerEventDefinition`` without its suffix), so a kind
compares equal to, prints as and is stored as that name. The groupings below -- which kinds
are events, activities, gateways, which catch and which throw -- are what the parser, the
deployer, the checker, the labels and discovery ask.
"""

from __future__ import annotations

from enum import StrEnum


class Kind(StrEnum):
    """A flow node: the local name of its BPMN element."""

    START_EVENT = "startEvent"
    END_EVENT = "endEvent"
    INTERMEDIATE_CATCH_EVENT = "intermediateCatchEvent"
    INTERMEDIATE_THROW_EVENT = "intermediateThrowEvent"
    BOUNDARY_EVENT = "boundaryEvent"
    IMPLICIT_THROW_EVENT = "implicitThrowEvent"
    TASK = "task"
    SCRIPT_TASK = "scriptTask"
    CALL_ACTIVITY = "callActivity"
    SUB_PROCESS = "subProcess"
    TRANSACTION = "transaction"
    AD_HOC_SUB_PROCESS = "adHocSubProcess"
    USER_TASK = "userTask"
    SERVICE_TASK = "serviceTask"
    SEND_TASK = "sendTask"
    RECEIVE_TASK = "receiveTask"
    MANUAL_TASK = "manualTask"
    BUSINESS_RULE_TASK = "businessRuleTask"
    EXCLUSIVE_GATEWAY = "exclusiveGateway"
    PARALLEL_GATEWAY = "parallelGateway"
    INCLUSIVE_GATEWAY = "inclusiveGateway"
    EVENT_BASED_GATEWAY = "eventBasedGateway"
    COMPLEX_GATEWAY = "complexGateway"


class EventKind(StrEnum):
    """What triggers or is thrown by an event: its event definition's name without
    ``EventDefinition`` (``none``: the event has none)."""

    NONE = "none"
    SIGNAL = "signal"
    MESSAGE = "message"
    TIMER = "timer"
    CONDITIONAL = "conditional"
    ERROR = "error"
    ESCALATION = "escalation"
    COMPENSATE = "compensate"
    TERMINATE = "terminate"
    CANCEL = "cancel"
    LINK = "link"


class LoopKind(StrEnum):
    """An activity's loop marker: ``standardLoopCharacteristics``, or
    ``multiInstanceLoopCharacteristics`` in parallel or one after the other."""

    STANDARD = "standard"
    PARALLEL = "parallel"
    SEQUENTIAL = "sequential"


class Run(StrEnum):
    """How the engine runs a node: the behaviour the deployer gives it
    (:mod:`robotale.fame_runtime.behaviours` has one function for each)."""

    START = "start"  # a none start event
    CATCH = "catch"  # waits for its trigger: a catching event, a receive task
    BOUNDARY = "boundary"  # leaves a boundary event once it fired
    PASS = "pass"  # throws and goes on: an intermediate throw event, a send task
    END = "end"
    TERMINATE = "terminate"
    TASK = "task"
    SCRIPT = "script"
    SKILL = "skill"  # a call activity bound to a Python skill
    CALL = "call"  # a call activity calling a process
    SUBPROCESS = "subprocess"
    EVENT_SUBPROCESS = "event_subprocess"
    LOOP = "loop"  # a loop or multi-instance activity around its body
    EXCLUSIVE_GATEWAY = Kind.EXCLUSIVE_GATEWAY.value
    PARALLEL_GATEWAY = Kind.PARALLEL_GATEWAY.value
    INCLUSIVE_GATEWAY = Kind.INCLUSIVE_GATEWAY.value
    EVENT_BASED_GATEWAY = Kind.EVENT_BASED_GATEWAY.value


EVENTS = frozenset(k for k in Kind if k.value.endswith("Event"))
GATEWAYS = frozenset(k for k in Kind if k.value.endswith("Gateway"))
ACTIVITIES = frozenset(Kind) - EVENTS - GATEWAYS
FLOW_NODES = frozenset(Kind)
#: activities with content of their own (a scope)
SCOPES = frozenset({Kind.SUB_PROCESS, Kind.TRANSACTION, Kind.AD_HOC_SUB_PROCESS})
#: tasks that send or receive a message: tagged by their own name, like any activity
MESSAGE_TASKS = frozenset({Kind.SEND_TASK, Kind.RECEIVE_TASK})
#: element kinds whose event definition waits for something (a signal catch is a subscriber)
CATCHING = frozenset(
    {Kind.START_EVENT, Kind.INTERMEDIATE_CATCH_EVENT, Kind.BOUNDARY_EVENT, Kind.RECEIVE_TASK}
)
#: element kinds whose event definition is thrown (a signal throw is a publisher)
THROWING = frozenset({Kind.INTERMEDIATE_THROW_EVENT, Kind.END_EVENT, Kind.SEND_TASK})
#: what may interrupt or start handling from outside: an event sub-process's start and a
#: boundary event take the same triggers
HANDLER_TRIGGERS = frozenset(
    {
        EventKind.SIGNAL,
        EventKind.TIMER,
        EventKind.CONDITIONAL,
        EventKind.ERROR,
        EventKind.MESSAGE,
        EventKind.ESCALATION,
        EventKind.COMPENSATE,
    }
)


def event_kind(name: str) -> EventKind | str:
    """The kind of an event definition named ``name`` (``signal`` for
    ``signalEventDefinition``); a name BPMN does not define stays as written, for the deployer
    to refuse."""
    try:
        return EventKind(name)
    except ValueError:
        return name
