"""Read BPMN 2.0 collaborations (.bpmn) into the typed model.

Reads what FAME's two modelers write: the thesis' ``ros:message``/``ros:payload``/
``data:parameters``/``qos:policy`` extension elements and Camunda's ``camunda:properties``/
``camunda:inputOutput``, matched by local name so any namespace URI or prefix works. It keeps
the authors' quirks readable: signals referenced before (or without) being declared, pools
without names, message flows, elements outside the FAME subset. A file that cannot be read
raises :class:`~robotale.errors.ModelError` naming the file, the line and the element id of
every problem at once; :func:`parse_all` gives the model with its problems listed instead, so
that ``robotale fame check`` can add what the deployer would refuse.
"""

from __future__ import annotations

import contextlib
from pathlib import Path
from xml.parsers import expat

from lxml import etree

from robotale.errors import ModelError
from robotale.fame_runtime.javascript import looks_like_javascript
from robotale.fame_runtime.kinds import FLOW_NODES, SCOPES, EventKind, Kind, LoopKind, event_kind
from robotale.fame_runtime.model import (
    JAVASCRIPT,
    PYTHON,
    DataObject,
    Definitions,
    EventDefinition,
    Expression,
    Flow,
    Loop,
    Node,
    Participant,
    Problem,
    Process,
    RosMessage,
    Scope,
)
from robotale.fame_runtime.qos import policy_name, qos_from_policies
from robotale.fame_runtime.timers import KINDS as TIMER_KINDS
from robotale.fame_runtime.timers import TimerSpec, parse_timer

BPMN_NS = "http://www.omg.org/spec/BPMN/20100524/MODEL"
_B = f"{{{BPMN_NS}}}"


#: what a data association may also point at in valid BPMN; the engine moves no data there
_NOT_DATA_OBJECTS = frozenset(
    ("dataObject", "dataStoreReference", "dataStore", "dataInput", "dataOutput", "property")
)

#: the children of extensionElements the engine reads (anything else is reported, not run)
_READ_EXTENSIONS = frozenset(
    (
        "properties",
        "property",
        "parameters",
        "parameter",
        "payload",
        "policies",
        "policy",
        "message",
        "process",
        "inputOutput",
        "inputParameter",
        "outputParameter",
        "list",
        "value",
        "map",
        "entry",
        "script",
        "qos",
    )
)


def parse(path: str | Path) -> Definitions:
    """The model of one .bpmn file; a ModelError naming every problem of the file."""
    definitions = parse_all(path)
    raise_problems(definitions)
    return definitions


def parse_bytes(data: bytes, file: str | Path = "<string>") -> Definitions:
    """The model of BPMN XML given as bytes; ``file`` names it in error messages."""
    definitions = parse_all_bytes(data, file)
    raise_problems(definitions)
    return definitions


def parse_all(path: str | Path) -> Definitions:
    """The model of one .bpmn file with what could not be read in ``problems`` (the rest of
    the file is still read). A file that is no readable XML is a ModelError."""
    path = Path(path)
    try:
        data = path.read_bytes()
    except OSError as error:
        raise ModelError(f"cannot read the BPMN file {path}: {error.strerror}") from error
    return parse_all_bytes(data, path)


def parse_all_bytes(data: bytes, file: str | Path = "<string>") -> Definitions:
    """:func:`parse_all` of BPMN XML given as bytes."""
    file = Path(file)
    root = _xml_root(data, file)
    definitions = _Reader(file).definitions(root)
    definitions.positions = _positions(data)
    definitions.problems = [definitions.placed(p) for p in definitions.problems]
    return definitions


def raise_problems(definitions: Definitions) -> None:
    """One ModelError listing every reading problem of ``definitions`` (none: nothing)."""
    found = definitions.problems
    if len(found) == 1:
        raise ModelError(str(found[0]), problems=found)
    if found:
        lines = "\n".join(str(p) for p in found)
        raise ModelError(f"{definitions.file}: {len(found)} problems:\n{lines}", problems=found)


def _positions(data: bytes) -> dict[str, tuple[int, int]]:
    """id -> (line, column) of each element's start tag (lxml keeps lines, not columns);
    the first element wins when an id is shared."""
    positions: dict[str, tuple[int, int]] = {}
    reader = expat.ParserCreate()

    def start(_name: str, attributes: dict[str, str]) -> None:
        ident = attributes.get("id")
        if ident and ident not in positions:
            positions[ident] = (reader.CurrentLineNumber, reader.CurrentColumnNumber + 1)

    reader.StartElementHandler = start
    # lxml read the file: what expat reads of it before any complaint is enough for columns
    with contextlib.suppress(expat.ExpatError):
        reader.Parse(data, True)
    return positions


def one_line(text: str | None) -> str:
    """A name as one line: line breaks and runs of spaces are one space."""
    return " ".join((text or "").split())


def _xml_root(data: bytes, file: Path) -> etree._Element:
    parser = etree.XMLParser(resolve_entities=False, no_network=True, remove_comments=True)
    try:
        root = etree.fromstring(data, parser)
    except etree.XMLSyntaxError as error:
        line, column = error.position if error.position else (error.lineno or 0, 0)
        problem = Problem(str(file), line or 0, "", f"malformed XML: {error.msg}", column or 0)
        raise ReadError(problem) from None
    if root.tag != f"{_B}definitions":
        raise ReadError(
            Problem(
                str(file),
                root.sourceline or 0,
                root.get("id", ""),
                f"not a BPMN 2.0 file: the root element is {etree.QName(root).localname}, not "
                f"bpmn:definitions of {BPMN_NS}",
            )
        )
    return root


class ReadError(ModelError):
    """A file that is no BPMN at all (not XML, another root): its one problem as data."""

    def __init__(self, problem: Problem) -> None:
        super().__init__(str(problem), problems=[problem])


def _local(element: etree._Element) -> str:
    tag = element.tag
    return tag.rsplit("}", 1)[-1] if isinstance(tag, str) else ""


def _bpmn_children(element: etree._Element, name: str) -> list[etree._Element]:
    return list(element.findall(f"{_B}{name}"))


def _text(element: etree._Element | None) -> str:
    return (element.text or "").strip() if element is not None else ""


class _Reader:
    """Reads one file; remembers it for error messages and for signal names."""

    def __init__(self, file: Path) -> None:
        self.file = file
        self.signals: dict[str, str] = {}
        self.errors: dict[str, str] = {}
        self.problems: list[Problem] = []  # every problem of the file, reported together
        self.warnings: list[str] = []
        self.language = ""  # the file's expressionLanguage as written, when it declares one

    def problem(self, line: int | None, message: str, element: str = "") -> None:
        self.problems.append(Problem(str(self.file), line or 0, element, message))

    def warn(self, line: int | None, message: str) -> None:
        self.warnings.append(f"{self.file}:{line or 0}: {message}")

    def definitions(self, root: etree._Element) -> Definitions:
        # Signals and errors first: the authors' models reference them before declaring them.
        self.signals = {s.get("id", ""): s.get("name", "") for s in root.iter(f"{_B}signal")}
        self.errors = {
            e.get("id", ""): e.get("name") or e.get("errorCode") or ""
            for e in root.iter(f"{_B}error")
        }
        self.messages = _names(root, "message", "name")
        self.data_stores = {
            e.get("id", "")
            for e in root.iter(f"{_B}dataStoreReference", f"{_B}dataStore")
            if e.get("id")
        }
        #: global tasks (10.2.4) a call activity may call: id -> their kind, as written
        global_tasks = {
            e.get("id", ""): _local(e)
            for e in root
            if isinstance(e.tag, str) and _local(e).startswith("global")
        }
        self.escalations = _names(root, "escalation", "escalationCode")
        self.language = (root.get("expressionLanguage") or "").strip()
        definitions = Definitions(self.file, root.get("id", ""), signals=dict(self.signals))
        definitions.errors = dict(self.errors)
        definitions.messages, definitions.escalations = self.messages, self.escalations
        definitions.global_tasks = global_tasks
        for element in _bpmn_children(root, "process"):
            process = self.process(element)
            process.definitions = definitions
            definitions.processes[process.id] = process
        for collaboration in _bpmn_children(root, "collaboration"):
            self.collaboration(collaboration, definitions)
        self.outside_pools(definitions)
        definitions.warnings = self.warnings
        definitions.problems = self.problems
        return definitions

    def outside_pools(self, definitions: Definitions) -> None:
        """With pools, a process that is in none is not run: say so."""
        if not definitions.participants:
            return
        pooled = {p.process_ref for p in definitions.participants}
        for process in definitions.processes.values():
            if process.id not in pooled:
                self.warn(
                    process.line,
                    f"process {process.describe()} is in no pool: it is not run (only a call "
                    "activity can call it)",
                )

    def collaboration(self, element: etree._Element, definitions: Definitions) -> None:
        for pool in _bpmn_children(element, "participant"):
            ref = _ref(pool, "processRef")
            if not ref:
                continue  # a black-box pool: nobody runs it
            if ref not in definitions.processes:
                self.problem(
                    pool.sourceline,
                    f"pool {pool.get('id')} refers to process {ref}, which is not in the file "
                    f"(processes: {', '.join(definitions.processes) or 'none'})",
                    pool.get("id", ""),
                )
                continue
            definitions.participants.append(self.participant(pool, definitions.processes[ref]))
        for flow in _bpmn_children(element, "messageFlow"):
            definitions.message_flows.append(
                (flow.get("id", ""), _ref(flow, "sourceRef"), _ref(flow, "targetRef"))
            )

    def participant(self, pool: etree._Element, process: Process) -> Participant:
        multiplicity = pool.find(f"{_B}participantMultiplicity")
        bound = (
            (_int_or_none(multiplicity.get("minimum")), _int_or_none(multiplicity.get("maximum")))
            if multiplicity is not None
            else (None, None)
        )
        name = one_line(pool.get("name")) or process.name or process.id
        return Participant(
            pool.get("id", ""),
            name,
            process.id,
            multi_instance=multiplicity is not None,
            minimum=bound[0],
            maximum=bound[1],
            line=pool.sourceline or 0,
        )

    def process(self, element: etree._Element) -> Process:
        process = Process(
            id=self.required_id(element),
            name=one_line(element.get("name")),
            executable=element.get("isExecutable", "true") != "false",
            line=element.sourceline or 0,
            file=self.file,
        )
        self.not_data_objects = {
            e.get("id", "")
            for e in element.iter()
            if isinstance(e.tag, str) and _local(e) in _NOT_DATA_OBJECTS
        }
        self.not_data_objects |= self.data_stores  # a store is the file's, whichever process
        # an association is an artifact of the process, wherever the elements it joins are
        self.associations: dict[str, list[str]] = {}
        for association in element.iter(f"{_B}association"):
            source, target = _ref(association, "sourceRef"), _ref(association, "targetRef")
            self.associations.setdefault(source, []).append(target)
        self.scope(element, process, process)
        self.check_data_associations(process)
        return process

    def required_id(self, element: etree._Element) -> str:
        identifier: str = element.get("id") or ""
        if not identifier:
            identifier = f"<{_local(element)} on line {element.sourceline}>"
            self.problem(
                element.sourceline, f'a bpmn:{_local(element)} has no id (add one: id="...")'
            )
        return identifier

    def scope(self, element: etree._Element, scope: Scope, process: Process) -> None:
        for child in element:
            kind = _local(child)
            if kind in FLOW_NODES:
                node = self.node(child, Kind(kind), process)
                scope.nodes[node.id] = node
            elif kind == "sequenceFlow":
                flow = self.flow(child)
                scope.flows[flow.id] = flow
            elif kind == "dataObjectReference":
                data_object = self.data_object(child, element)
                process.data_objects[data_object.id] = data_object
            elif kind == "association":
                source, target = _ref(child, "sourceRef"), _ref(child, "targetRef")
                scope.associations.setdefault(source, []).append(target)
        self.check_flows(scope)
        self.compensation_handlers(scope)

    def check_flows(self, scope: Scope) -> None:
        for flow in scope.flows.values():
            for end, ref in (("source", flow.source), ("target", flow.target)):
                if ref not in scope.nodes:
                    where = f" ({ref})" if ref else ""
                    self.problem(
                        flow.line,
                        f"sequence flow {flow.id} is dangling: its {end}{where} is not an "
                        "element of the same process or sub-process",
                        flow.id,
                    )
        for flow_id in [f.id for f in scope.flows.values() if not _joined(f, scope)]:
            del scope.flows[flow_id]  # reported above; the rest of the file is still read
        for node in scope.nodes.values():
            if node.kind == Kind.BOUNDARY_EVENT and node.attached_to not in scope.nodes:
                self.problem(
                    node.line,
                    f"boundary event {node.id} is attached to {node.attached_to or 'nothing'}, "
                    "which is not in the same process (attach it to an activity beside it)",
                    node.id,
                )
        self.unconditioned_choices(scope)

    def unconditioned_choices(self, scope: Scope) -> None:
        """An exclusive gateway with several unconditioned flows takes the first: say so."""
        for node in scope.nodes.values():
            if node.kind != Kind.EXCLUSIVE_GATEWAY:
                continue
            bare = [
                f.id
                for f in scope.flows.values()
                if f.source == node.id and f.condition is None and f.id != node.default_flow
            ]
            if len(bare) > 1:
                self.warn(
                    node.line,
                    f"exclusiveGateway {node.describe()} has {len(bare)} outgoing flows without "
                    f"a condition ({', '.join(bare)}): the engine takes the first, {bare[0]}",
                )

    def compensation_handlers(self, scope: Scope) -> None:
        """A compensation boundary event names its handler by an association (10.6.5)."""
        for node in scope.nodes.values():
            if node.kind != Kind.BOUNDARY_EVENT or node.event_kind != EventKind.COMPENSATE:
                continue
            targets = [t for t in self.associations.get(node.id, ()) if t in scope.nodes]
            handlers = [t for t in targets if scope.nodes[t].for_compensation]
            if len(handlers) == 1:
                node.compensation_handler = handlers[0]
                continue
            found = ", ".join(targets) or "nothing"
            self.problem(
                node.line,
                f"compensation boundary event {node.describe()} is associated with {found}: "
                "it needs an association to exactly one activity marked "
                'isForCompensation="true" beside it (its compensation handler)',
                node.id,
            )

    def check_data_associations(self, process: Process) -> None:
        for node in process.walk():
            for refs in (node.data_inputs, node.data_outputs):
                for ref in list(refs):
                    if ref in process.data_objects:
                        continue
                    refs.remove(ref)
                    if ref in self.not_data_objects:
                        continue  # a data store, an input/output or a property: valid BPMN
                    self.problem(
                        node.line,
                        f"{node.kind} {node.id} has a data association with {ref or 'nothing'}, "
                        "which is no data object, data object reference, data store reference, "
                        f"input, output or property of process {process.id}",
                        node.id,
                    )

    def node(self, element: etree._Element, kind: Kind, process: Process) -> Node:
        node = Node(
            id=self.required_id(element),
            kind=kind,
            name=one_line(element.get("name")),
            line=element.sourceline or 0,
            attached_to=_ref(element, "attachedToRef"),
            cancel_activity=element.get("cancelActivity", "true") != "false",
            interrupting=element.get("isInterrupting", "true") != "false",
            default_flow=element.get("default", ""),
            called_element=_ref(element, "calledElement"),
            triggered_by_event=element.get("triggeredByEvent") == "true",
        )
        node.events = [self.event_definition(d, node) for d in element if _is_definition(d)]
        if kind in (Kind.SEND_TASK, Kind.RECEIVE_TASK):  # its message, like a message event's
            ref = _ref(element, "messageRef")
            node.events = [EventDefinition(EventKind.MESSAGE, ref, self.messages.get(ref, ""))]
        self.data_associations(element, node)
        self.markers(element, node)
        extensions = _Extensions(element.find(f"{_B}extensionElements"))
        for ignored in extensions.ignored:
            self.warn(node.line, f"{kind} {node.describe()}: {ignored} is ignored (not run)")
        node.inputs, node.outputs = extensions.inputs, extensions.outputs
        if node.events and node.events[0].kind in (
            EventKind.SIGNAL,
            EventKind.ERROR,
            EventKind.MESSAGE,
        ):
            node.message = self.ros_message(extensions, element, node)
        if kind == Kind.SCRIPT_TASK:
            node.script = self.script(element, node)
        if kind == Kind.CALL_ACTIVITY and extensions.embedded_process:
            node.embedded_process = self.embedded_process(extensions.embedded_process, element)
        if kind in SCOPES:
            node.scope = Scope()
            self.scope(element, node.scope, process)
        return node

    def markers(self, element: etree._Element, node: Node) -> None:
        for child in element:
            if _local(child) == "standardLoopCharacteristics":
                node.loop = self.standard_loop(child, node)
            elif _local(child) == "multiInstanceLoopCharacteristics":
                node.loop = self.multi_instance(child, node)
        node.for_compensation = element.get("isForCompensation") == "true"

    def standard_loop(self, element: etree._Element, node: Node) -> Loop:
        maximum = (element.get("loopMaximum") or "").strip() or None  # "" is as good as none
        if maximum is not None and _int_or_none(maximum) is None:
            self.problem(
                element.sourceline,
                f"the loop of {node.kind} {node.id} has loopMaximum {maximum!r}, which is no "
                'whole number (write e.g. loopMaximum="5")',
                node.id,
            )
        return Loop(
            LoopKind.STANDARD,
            condition=self.loop_expression(element, "loopCondition", node),
            test_before=element.get("testBefore") == "true",
            maximum=_int_or_none(maximum),
        )

    def multi_instance(self, element: etree._Element, node: Node) -> Loop:
        """Cardinality or collection, the item variables and the completion condition, in
        the standard elements or Camunda's attributes."""
        item = element.find(f"{_B}inputDataItem")
        output_item = element.find(f"{_B}outputDataItem")
        collection = _text(element.find(f"{_B}loopDataInputRef"))
        collection = collection or _unwrap(element.get(_CAMUNDA + "collection") or "")
        loop = Loop(
            LoopKind.SEQUENTIAL if element.get("isSequential") == "true" else LoopKind.PARALLEL,
            cardinality=self.loop_expression(element, "loopCardinality", node),
            collection=collection,
            element=_item_name(item) or (element.get(_CAMUNDA + "elementVariable") or ""),
            output_collection=_text(element.find(f"{_B}loopDataOutputRef")),
            output_element=_item_name(output_item),
            condition=self.loop_expression(element, "completionCondition", node),
        )
        return loop  # without cardinality or collection it is valid BPMN the deployer refuses

    def loop_expression(self, element: etree._Element, name: str, node: Node) -> Expression | None:
        """``loopCardinality``, ``loopCondition`` or ``completionCondition``; Camunda's
        ``${...}`` wrapping is taken off (the expression inside is what runs)."""
        child = element.find(f"{_B}{name}")
        text = _unwrap(_text(child))
        return self.expression(child, text, node.id) if text else None

    def data_associations(self, element: etree._Element, node: Node) -> None:
        for assoc in _bpmn_children(element, "dataInputAssociation"):
            node.data_inputs += [_text(r) for r in _bpmn_children(assoc, "sourceRef")]
        for assoc in _bpmn_children(element, "dataOutputAssociation"):
            node.data_outputs += [_text(r) for r in _bpmn_children(assoc, "targetRef")]

    def event_definition(self, element: etree._Element, node: Node) -> EventDefinition:
        kind = _local(element).removesuffix("EventDefinition")
        if kind == EventKind.SIGNAL:
            ref = _ref(element, "signalRef")
            return EventDefinition(EventKind.SIGNAL, ref, self.signals.get(ref, ""))
        if kind == EventKind.ERROR:
            ref = _ref(element, "errorRef")
            return EventDefinition(EventKind.ERROR, ref, self.errors.get(ref, ""))
        if kind == EventKind.TIMER:
            return EventDefinition(EventKind.TIMER, timer=self.timer(element, node))
        if kind == EventKind.MESSAGE:
            ref = _ref(element, "messageRef")
            return EventDefinition(EventKind.MESSAGE, ref, self.messages.get(ref, ""))
        if kind == EventKind.COMPENSATE:
            wait = element.get("waitForCompletion", "true") != "false"
            return EventDefinition(EventKind.COMPENSATE, _ref(element, "activityRef"), wait=wait)
        if kind == EventKind.ESCALATION:
            ref = _ref(element, "escalationRef")
            return EventDefinition(EventKind.ESCALATION, ref, self.escalations.get(ref, ""))
        if kind == EventKind.CONDITIONAL:
            condition = element.find(f"{_B}condition")
            text = _text(condition)
            expression = self.expression(condition, text, node.id) if text else None
            return EventDefinition(EventKind.CONDITIONAL, condition=expression)
        return EventDefinition(event_kind(kind), _ref(element, "messageRef"))

    def timer(self, element: etree._Element, node: Node) -> TimerSpec | None:
        for child in element:
            if _local(child) in TIMER_KINDS:
                if not _text(child):
                    continue  # an empty <timeDate/>: a gap the deployer reports as such
                try:
                    return parse_timer(_local(child), _text(child))
                except ValueError as error:
                    self.problem(
                        child.sourceline,
                        f"timer event {node.describe()} is malformed: {error}",
                        node.id,
                    )
        return None

    def expression(self, element: etree._Element, text: str, element_id: str) -> Expression:
        """A condition in the language its element or the file names (as written, for
        messages); without one, JavaScript or Python by its look, else the standard's XPath
        (see :func:`~robotale.fame_runtime.expressions.compile_condition`)."""
        language = (element.get("language") or self.language).strip()
        line = element.sourceline or 0
        if _is_javascript(language.lower()) or (not language and looks_like_javascript(text)):
            return Expression(text, JAVASCRIPT, element_id, line)
        if language.lower() in ("python", "py", "python3"):
            language = PYTHON
        return Expression(text, language or PYTHON, element_id, line, stated=bool(language))

    def flow(self, element: etree._Element) -> Flow:
        flow = Flow(
            id=self.required_id(element),
            source=element.get("sourceRef", ""),
            target=element.get("targetRef", ""),
            name=one_line(element.get("name")),
            line=element.sourceline or 0,
        )
        condition = element.find(f"{_B}conditionExpression")
        if condition is not None and _text(condition):
            flow.condition = self.expression(condition, _text(condition), flow.id)
        return flow

    def script(self, element: etree._Element, node: Node) -> Expression:
        body = element.find(f"{_B}script")
        text = body.text if body is not None and body.text else ""
        script_format = (element.get("scriptFormat") or "").strip()
        lowered = script_format.lower()
        if _is_javascript(lowered) or (not script_format and looks_like_javascript(text)):
            language = JAVASCRIPT
        elif not script_format or lowered in ("python", "py", "python3"):
            language = PYTHON
        else:
            language = script_format
        return Expression(text, language, node.id, body.sourceline if body is not None else 0)

    def data_object(self, element: etree._Element, container: etree._Element) -> DataObject:
        ref = _ref(element, "dataObjectRef")
        target = next(
            (d for d in _bpmn_children(container, "dataObject") if d.get("id") == ref), None
        )
        name = element.get("name") or (target.get("name") if target is not None else "") or ""
        extensions = _Extensions(element.find(f"{_B}extensionElements"))
        parameters = {**extensions.properties, **extensions.parameters}
        return DataObject(
            self.required_id(element), one_line(name), parameters, element.sourceline or 0
        )

    def ros_message(
        self, extensions: _Extensions, element: etree._Element, node: Node
    ) -> RosMessage:
        properties = dict(extensions.properties)
        listed = extensions.signal_list(node.name)
        msgtype = extensions.msgtype or properties.pop("type", "") or (listed[0] if listed else "")
        payload: dict[str, str] | str | None = extensions.payload
        if payload is None and "payload" in properties:
            payload = properties.pop("payload")
        if payload is None and len(listed) > 1:
            payload = listed[1]
        policies = dict(extensions.policies)
        policies.update({k: v for k, v in properties.items() if policy_name(k)})
        try:
            qos = qos_from_policies(policies)
        except ValueError as error:
            self.problem(element.sourceline, f"signal event {node.describe()}: {error}", node.id)
            return RosMessage(msgtype.strip(), payload)
        return RosMessage(msgtype.strip(), payload, qos, bool(policies))

    def embedded_process(self, text: str, element: etree._Element) -> Process | None:
        wrapped = (
            f'<bpmn:definitions xmlns:bpmn="{BPMN_NS}" '
            'xmlns:xsi="http://www.w3.org/2001/XMLSchema-instance" '
            'xmlns:camunda="http://camunda.org/schema/1.0/bpmn">'
            f"{text}</bpmn:definitions>"
        ).encode()
        ident = element.get("id", "")
        try:
            definitions = parse_bytes(wrapped, self.file)
        except ModelError as error:
            self.problem(
                element.sourceline,
                f"the process embedded in call activity {ident} is unreadable: {error}",
                ident,
            )
            return None
        if not definitions.processes:
            self.problem(
                element.sourceline,
                f"call activity {ident} embeds no bpmn:process (embed one, or name a "
                "calledElement)",
                ident,
            )
            return None
        return next(iter(definitions.processes.values()))


_CAMUNDA = "{http://camunda.org/schema/1.0/bpmn}"


def _names(root: etree._Element, tag: str, fallback: str) -> dict[str, str]:
    """id -> name of every ``bpmn:<tag>`` (its ``fallback`` attribute when it has no name)."""
    return {
        e.get("id", ""): one_line(e.get("name") or e.get(fallback)) for e in root.iter(f"{_B}{tag}")
    }


def _ref(element: etree._Element, attribute: str) -> str:
    """A reference as written, without the namespace prefix a QName reference may carry
    (``processRef="bpmn2:Process_1"``, the prefix declared in the file)."""
    value = (element.get(attribute) or "").strip()
    prefix, colon, local = value.partition(":")
    return local if colon and prefix in (element.nsmap or {}) else value


def _unwrap(text: str) -> str:
    """``${items}`` -> ``items``: Camunda writes expressions inside ``${}``."""
    text = text.strip()
    return text[2:-1].strip() if text.startswith("${") and text.endswith("}") else text


def _item_name(element: etree._Element | None) -> str:
    """The variable an ``inputDataItem``/``outputDataItem`` stands for: its id (as
    SpiffWorkflow reads it), else its name."""
    if element is None:
        return ""
    return (element.get("id") or element.get("name") or "").strip()


def _is_definition(element: etree._Element) -> bool:
    return _local(element).endswith("EventDefinition") and isinstance(element.tag, str)


def _joined(flow: Flow, scope: Scope) -> bool:
    return flow.source in scope.nodes and flow.target in scope.nodes


def _int_or_none(text: str | None) -> int | None:
    return int(text) if text and text.strip().isdigit() else None


class _Extensions:
    """What one ``bpmn:extensionElements`` holds, whatever the modeler that wrote it."""

    def __init__(self, element: etree._Element | None) -> None:
        self.properties: dict[str, str] = {}
        self.parameters: dict[str, str] = {}
        self.policies: dict[str, str] = {}
        self.inputs: dict[str, object] = {}
        self.outputs: dict[str, object] = {}
        self.payload: dict[str, str] | None = None
        self.msgtype = ""
        self.embedded_process = ""
        self.ignored: list[str] = []  # extensions the engine does not run, as prefix:name
        if element is not None:
            for child in element.iter():
                self.read(child)
            ignored = [
                f"{child.prefix or 'extension'}:{_local(child)}"
                for child in element
                if isinstance(child.tag, str) and _local(child) not in _READ_EXTENSIONS
            ]
            self.ignored = list(dict.fromkeys(ignored))  # each kind once

    def read(self, child: etree._Element) -> None:
        kind, parent = _local(child), _local(child.getparent())
        if kind == "property" and parent == "properties":
            self.properties[child.get("name", "")] = child.get("value") or _text(child)
        elif kind == "parameter" and parent == "payload":
            self.payload = self.payload or {}
            self.payload[child.get("name", "").rstrip(":")] = child.get("value", "")
        elif kind == "parameter" and parent == "parameters":
            self.parameters[child.get("name", "")] = child.get("value", "")
        elif kind == "policy":
            self.policies[child.get("name", "")] = child.get("value", "")
        elif kind == "message" and child.get("type"):
            self.msgtype = child.get("type", "")
        elif kind == "process" and child.get("process"):
            self.embedded_process = child.get("process", "")
        elif kind in ("inputParameter", "outputParameter"):
            target = self.inputs if kind == "inputParameter" else self.outputs
            target[child.get("name", "")] = _parameter_value(child)

    def signal_list(self, name: str) -> list[str]:
        """Camunda flavour of a signal: an input parameter holding the list [type, payload]."""
        for key, value in self.inputs.items():
            if isinstance(value, list) and (key == name or len(self.inputs) == 1):
                return [str(v) for v in value]
        return []


def _parameter_value(element: etree._Element) -> object:
    """A camunda input/output parameter: text, a list of texts or a map of texts."""
    for child in element:
        kind = _local(child)
        if kind == "list":
            return [_text(v) for v in child if _local(v) == "value"]
        if kind == "map":
            return {e.get("key", ""): _text(e) for e in child if _local(e) == "entry"}
        if kind == "script":
            return _text(child)
    return _text(element)


def _is_javascript(language: str) -> bool:
    """``javascript``, ``text/javascript``, ``js``, ``ecmascript`` and the like."""
    language = language.rsplit("/", 1)[-1]
    return language.startswith(("javascript", "ecmascript")) or language in ("js", "es6")
