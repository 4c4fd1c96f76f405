"""The typed model a BPMN collaboration is read into.

Both extension flavours found in FAME models -- the thesis' ``ros:``/``data:``/``qos:`` elements
and Camunda's ``camunda:properties``/``camunda:inputOutput`` -- end up in the same fields here,
so nothing after the parser knows which modeler wrote a file. The model keeps everything the
file says, including elements the engine cannot run: refusing those is the deployer's job
(:mod:`robotale.fame_runtime.plan`), so that ``robotale fame check`` can list them all.
"""

from __future__ import annotations

from collections.abc import Iterator
from dataclasses import dataclass, field
from pathlib import Path

from robotale.fame_runtime.kinds import EventKind, Kind, LoopKind
from robotale.fame_runtime.qos import DEFAULT_QOS, QoS
from robotale.fame_runtime.timers import TimerSpec

PYTHON, JAVASCRIPT = "python", "javascript"
#: the expression language BPMN 2.0 assumes when a file names none (section 8.3.1)
XPATH = "http://www.w3.org/1999/XPath"


@dataclass(frozen=True, slots=True)
class Problem:
    """One thing robotale cannot read or run in a file: where, which element, and a sentence
    saying what is wrong and what would be accepted."""

    file: str
    line: int
    element: str  # the element's id ("" for the file as a whole)
    sentence: str
    column: int = 0  # 0 when unknown

    def __str__(self) -> str:
        return f"{self.file}:{self.line}: {self.sentence}"

    def as_dict(self) -> dict[str, object]:
        return {
            "element": self.element,
            "file": self.file,
            "line": self.line,
            "column": self.column,
            "sentence": self.sentence,
        }


@dataclass(frozen=True, slots=True)
class Expression:
    """A condition or script as written in the model, with where it was written."""

    text: str
    language: str  # python | javascript | the language URI or scriptFormat as written
    element_id: str
    line: int = 0
    #: False when neither the element nor the file names a language: robotale reads Python
    #: or JavaScript then, and anything else as the standard's default, XPath
    stated: bool = True


@dataclass(frozen=True, slots=True)
class RosMessage:
    """The ROS side of a signal event: message type, payload template, QoS (guideline G3).

    ``payload`` is either a mapping of (possibly dotted) field name to value template
    (``ros:parameter``) or one JSON text template (Camunda's ``payload`` property), in both
    cases with ``${expression}`` placeholders filled in when the signal is thrown.
    """

    msgtype: str = ""
    payload: dict[str, str] | str | None = None
    qos: QoS = DEFAULT_QOS
    qos_given: bool = False


@dataclass(frozen=True, slots=True)
class EventDefinition:
    """What triggers or is thrown by an event."""

    #: what it is; a definition BPMN does not name (``fooEventDefinition``) stays as written
    kind: EventKind | str
    ref: str = ""  # signalRef / errorRef / messageRef / compensation's activityRef as written
    ref_name: str = ""  # the name of the referenced signal / error, "" when not declared
    timer: TimerSpec | None = None
    condition: Expression | None = None
    wait: bool = True  # a compensation throw's waitForCompletion


@dataclass(frozen=True, slots=True)
class Loop:
    """A loop or multi-instance marker of an activity (BPMN 2.0 section 10.3.8).

    ``kind`` is ``standard`` (``standardLoopCharacteristics``), ``parallel`` or ``sequential``
    (``multiInstanceLoopCharacteristics``). Names of variables are as the file gives them:
    ``loopDataInputRef``/``camunda:collection`` and ``inputDataItem``/
    ``camunda:elementVariable`` (the item's id, as SpiffWorkflow reads it).
    """

    kind: LoopKind
    cardinality: Expression | None = None
    collection: str = ""  # the variable holding the input collection
    element: str = ""  # the variable each instance finds its item in
    output_collection: str = ""
    output_element: str = ""
    condition: Expression | None = None  # loopCondition (standard) / completionCondition
    test_before: bool = False
    maximum: int | None = None


@dataclass(slots=True)
class DataObject:
    """A data object reference and its parameters (``${var}`` = filled in at run time)."""

    id: str
    name: str
    parameters: dict[str, str]
    line: int = 0


@dataclass(slots=True)
class Flow:
    id: str
    source: str
    target: str
    name: str = ""
    condition: Expression | None = None
    line: int = 0


@dataclass(slots=True)
class Node:
    """One flow node (event, activity, gateway) of a process or sub-process."""

    id: str
    kind: Kind  # the BPMN tag: startEvent, scriptTask, exclusiveGateway, subProcess ...
    name: str = ""
    line: int = 0
    events: list[EventDefinition] = field(default_factory=list)
    message: RosMessage | None = None
    script: Expression | None = None
    called_element: str = ""
    embedded_process: Process | None = None  # FAME-modeler's callActivity:process
    attached_to: str = ""  # boundary events
    cancel_activity: bool = True  # boundary events
    interrupting: bool = True  # start events of event sub-processes
    default_flow: str = ""
    data_inputs: list[str] = field(default_factory=list)  # data object reference ids
    data_outputs: list[str] = field(default_factory=list)
    inputs: dict[str, object] = field(default_factory=dict)  # camunda:inputParameter
    outputs: dict[str, object] = field(default_factory=dict)  # camunda:outputParameter
    scope: Scope | None = None  # sub-process content
    triggered_by_event: bool = False
    loop: Loop | None = None  # a loop or multi-instance marker
    quirks: list[str] = field(default_factory=list)  # what the engine would have to refuse
    for_compensation: bool = False  # isForCompensation: run only to compensate another
    compensation_handler: str = ""  # a compensation boundary event: its handler's id

    @property
    def event(self) -> EventDefinition | None:
        return self.events[0] if self.events else None

    @property
    def event_kind(self) -> EventKind | str:
        """``none`` for an event without a definition, else the definition's kind."""
        return self.events[0].kind if self.events else EventKind.NONE

    def describe(self) -> str:
        """``Activity_1 (Take Off)``: how messages name this element."""
        return f"{self.id} ({self.name})" if self.name and self.name != self.id else self.id


@dataclass(slots=True)
class Scope:
    """The content of a process or sub-process: nodes and sequence flows, in file order."""

    nodes: dict[str, Node] = field(default_factory=dict)
    flows: dict[str, Flow] = field(default_factory=dict)
    #: bpmn:association source -> targets (a compensation boundary event -> its handler)
    associations: dict[str, list[str]] = field(default_factory=dict)


@dataclass(slots=True)
class Process(Scope):
    id: str = ""
    name: str = ""
    executable: bool = True
    line: int = 0
    file: Path | None = None
    #: every data object reference of the process, sub-processes included (associations
    #: may cross scopes)
    data_objects: dict[str, DataObject] = field(default_factory=dict)
    definitions: Definitions | None = field(default=None, repr=False)

    def describe(self) -> str:
        return f"{self.id} ({self.name})" if self.name and self.name != self.id else self.id

    def walk(self) -> Iterator[Node]:
        """Every node of the process, those of sub-processes included."""
        stack: list[Scope] = [self]
        while stack:
            scope = stack.pop()
            for node in scope.nodes.values():
                yield node
                if node.scope is not None:
                    stack.append(node.scope)


@dataclass(slots=True)
class Participant:
    """A pool: one robot (single instance) or a robot type (multi-instance, guideline G1)."""

    id: str
    name: str
    process_ref: str
    multi_instance: bool = False
    minimum: int | None = None
    maximum: int | None = None
    line: int = 0


@dataclass(slots=True)
class Definitions:
    """One .bpmn file."""

    file: Path
    id: str = ""
    processes: dict[str, Process] = field(default_factory=dict)
    participants: list[Participant] = field(default_factory=list)
    signals: dict[str, str] = field(default_factory=dict)  # id -> name
    errors: dict[str, str] = field(default_factory=dict)  # id -> name (or errorCode)
    messages: dict[str, str] = field(default_factory=dict)  # id -> name
    escalations: dict[str, str] = field(default_factory=dict)  # id -> name (or code)
    global_tasks: dict[str, str] = field(default_factory=dict)  # id -> globalUserTask ...
    message_flows: list[tuple[str, str, str]] = field(default_factory=list)
    #: silent choices made visible: "<file>:<line>: <element> <what happens>"
    warnings: list[str] = field(default_factory=list)
    #: what could not be read (only when read with ``parse_all``; ``parse`` raises instead)
    problems: list[Problem] = field(default_factory=list)
    #: element id -> (line, column) of its start tag, for reports that name columns
    positions: dict[str, tuple[int, int]] = field(default_factory=dict, repr=False)

    def placed(self, problem: Problem) -> Problem:
        """``problem`` with the column of its element's start tag, when that element starts
        on the problem's line of this file."""
        line, column = self.positions.get(problem.element, (0, 0))
        if problem.column or line != problem.line or problem.file != str(self.file):
            return problem
        return Problem(problem.file, problem.line, problem.element, problem.sentence, column)

    def pools(self) -> list[tuple[Participant, Process]]:
        """Every pool with the process it holds; a file without a collaboration has one pool
        per process, named after the process."""
        if self.participants:
            return [
                (p, self.processes[p.process_ref])
                for p in self.participants
                if p.process_ref in self.processes
            ]
        return [
            (Participant(proc.id, proc.name or proc.id, proc.id, line=proc.line), proc)
            for proc in self.processes.values()
        ]
