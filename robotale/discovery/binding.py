"""What each discovered activity runs: the skill binding that makes a discovered model run.

A discovered activity is only a name in the log. To run, the engine needs a skill and its
inputs, a script, or a timer. The binding says which, from two sources:

- **the skill registry** (the simulator's skills by default): an activity whose skill name
  (``go_to`` -> ``GoTo``) the registry has calls that skill; one it lacks calls the skill of
  its name all the same, so ``fame check`` names exactly the skills the simulation lacks;
- **a driving model** (``--bind DRIVING.bpmn``): an element of the same pool (matched by name)
  that the engine tags with the same label gives its kind and what it runs: a call
  activity's ``calledElement``, inputs and loop marker, a script task's script, a timer's
  duration (a timer event tagged as an activity becomes a timer catch event), a signal event's
  message type, payload and the data objects its message fills. A message a pool's robots
  sent or received that the driving pool has no event for comes from a skill (the simulated
  drone's Explore throws ``job`` itself): it is left out of the discovered process, as
  conformance leaves it out of the replay, so the skill's own message is not sent twice.

Copied elements keep their namespaces (``camunda:``, ``ros:`` ...), which the engine's parser
reads by local name.
"""

from __future__ import annotations

import copy
import re
from collections.abc import Iterable
from dataclasses import dataclass, field
from pathlib import Path

from lxml import etree

from robotale.errors import InputError
from robotale.fame_runtime.labels import RECEIVE, SEND, activity_label

BPMN = "http://www.omg.org/spec/BPMN/20100524/MODEL"
#: BPMN elements the engine tags as activities, copied with their own element name
ACTIVITIES = frozenset(
    {
        "callActivity",
        "scriptTask",
        "task",
        "serviceTask",
        "userTask",
        "manualTask",
        "sendTask",
        "receiveTask",
        "businessRuleTask",
    }
)
#: children that belong to the driving model's graph, never copied
#: ... nor a standard loop: the log has each pass as an instance of its own, so the
#: discovered process repeats the activity itself
_GRAPH = frozenset({"incoming", "outgoing", "documentation", "standardLoopCharacteristics"})
#: a multi-instance marker becomes one instance per pass, for the same reason; it stays so
#: that what the activity reads of its instance (``loopCounter``) is there
ONE_INSTANCE = (
    f'<bpmn:multiInstanceLoopCharacteristics xmlns:bpmn="{BPMN}">'
    "<bpmn:loopCardinality>1</bpmn:loopCardinality></bpmn:multiInstanceLoopCharacteristics>"
)
_ASSOCIATIONS = frozenset({"dataInputAssociation", "dataOutputAssociation"})
_EVENTS = frozenset(
    {"startEvent", "intermediateCatchEvent", "intermediateThrowEvent", "boundaryEvent", "endEvent"}
)


@dataclass(frozen=True, slots=True)
class Bound:
    """How one discovered element runs: ``tag`` its BPMN element name (``callActivity``,
    ``scriptTask``, ``intermediateCatchEvent`` for a timer ...), ``attributes`` besides id and
    name, ``body`` the XML of its children, ``data`` the data objects it reads or fills."""

    tag: str
    attributes: tuple[tuple[str, str], ...] = ()
    body: str = ""
    data: tuple[tuple[str, str], ...] = ()  # (id, XML) of data objects to add to the process
    origin: str = ""


@dataclass(slots=True)
class Bindings:
    """Per pool, per activity label, how the discovered element runs."""

    skills: frozenset[str]
    pools: dict[str, dict[str, Bound]] = field(default_factory=dict)
    #: per pool, message labels a skill sends or consumes itself: not events of the process
    outside: dict[str, set[str]] = field(default_factory=dict)
    #: (pool, trigger) -> seconds after an instance began that a handler's timer fired
    timers: dict[tuple[str, str], float] = field(default_factory=dict)
    #: (pool, activity) -> the times in a row its robots always did it
    repeats: dict[tuple[str, str], int] = field(default_factory=dict)
    driving: Path | None = None

    def of(self, pool: str, label: str) -> Bound | None:
        return self.pools.get(pool, {}).get(label)

    def is_timer(self, pool: str, label: str) -> bool:
        """Whether the driving model's element of ``label`` is a timer."""
        bound = self.of(pool, label)
        return bound is not None and "timerEventDefinition" in bound.body

    def lacking(self, pool: str, labels: Iterable[str]) -> dict[str, list[str]]:
        """The skills the activities ``labels`` of ``pool`` would call that the registry
        lacks (no driving element binds them): skill -> the activities calling it."""
        found: dict[str, list[str]] = {}
        for label in labels:
            if self.of(pool, label) is None and skill_name(label) not in self.skills:
                found.setdefault(skill_name(label), []).append(label)
        return found

    def skill(self, label: str) -> Bound:
        """The registry's binding: a call of the skill the label names."""
        return Bound("callActivity", (("calledElement", skill_name(label)),), origin="registry")


def skill_name(label: str) -> str:
    """The skill an activity calls: ``take_off`` -> ``TakeOff`` (the inverse of the engine's
    tag names, :func:`activity_label`)."""
    return "".join(part[:1].upper() + part[1:] for part in re.split(r"[^0-9a-zA-Z]+", label))


def simulator_skills() -> frozenset[str]:
    """The skills the simulator's robots have."""
    # the simulator (0.8 s to import) only when binding to its skills
    from robotale.sim.skills import SKILLS

    return frozenset(SKILLS)


def bind(
    pools: Iterable[str],
    driving: Path | None = None,
    skills: Iterable[str] | None = None,
) -> Bindings:
    """The bindings of the discovered ``pools`` (names): the registry's ``skills`` (the
    simulator's by default), and with ``driving`` every same-named element of its pools."""
    bindings = Bindings(frozenset(simulator_skills() if skills is None else skills))
    if driving is None:
        return bindings
    bindings.driving = Path(driving)
    root = _read(Path(driving))
    processes = _processes_by_pool(root)
    for pool in pools:
        process = processes.get(_key(pool))
        if process is None:
            continue
        bound, events = _elements(process, root, Path(driving).name)
        bindings.pools[pool] = bound
        bindings.outside[pool] = events
    return bindings


def _read(path: Path) -> etree._Element:
    try:
        return etree.parse(
            str(path), etree.XMLParser(resolve_entities=False, no_network=True)
        ).getroot()
    except (OSError, etree.XMLSyntaxError) as error:
        raise InputError(f"--bind {path}: not a readable BPMN file ({error})") from None


def _key(name: str) -> str:
    return re.sub(r"[^0-9a-z]", "", name.lower())


def _processes_by_pool(root: etree._Element) -> dict[str, etree._Element]:
    processes = {p.get("id"): p for p in root.iter(f"{{{BPMN}}}process")}
    found = {}
    for participant in root.iter(f"{{{BPMN}}}participant"):
        process = processes.get(participant.get("processRef"))
        if process is not None:
            found[_key(participant.get("name") or participant.get("id") or "")] = process
    for process in processes.values():  # a lone process is its own pool
        found.setdefault(_key(process.get("name") or process.get("id") or ""), process)
    return found


def _local(element: etree._Element) -> str:
    return etree.QName(element).localname if isinstance(element.tag, str) else ""


def _elements(
    process: etree._Element, root: etree._Element, file: str
) -> tuple[dict[str, Bound], set[str]]:
    """The bindings of one driving process' elements by label, and the signals it has events
    for (``job!``, ``job?``)."""
    signals = {s.get("id"): s.get("name") or s.get("id") for s in root.iter(f"{{{BPMN}}}signal")}
    data = _data_objects(process)
    bound: dict[str, Bound] = {}
    events: set[str] = set()
    for element in process.iter():
        kind = _local(element)
        origin = f"{file} {kind} {element.get('id')}"
        if kind in ACTIVITIES:
            label = activity_label(element.get("name") or "", element.get("id") or "")
            bound.setdefault(label, _activity(element, kind, data, origin))
        elif kind in ("subProcess", "transaction", "adHocSubProcess"):
            # the log has its inner activities as the robot's own steps: the sub-process
            # itself is only the tag around them
            label = activity_label(element.get("name") or "", element.get("id") or "")
            bound.setdefault(label, Bound("task", origin=origin))
        elif kind in _EVENTS:
            for definition in element:
                what = _local(definition)
                if what == "signalEventDefinition":
                    name = signals.get(definition.get("signalRef"), definition.get("signalRef"))
                    throws = kind in ("intermediateThrowEvent", "endEvent")
                    label = f"{name}{SEND if throws else RECEIVE}"
                    events.add(label)
                    bound.setdefault(label, _signal(element, data, origin))
                elif what in ("timerEventDefinition", "conditionalEventDefinition"):
                    label = activity_label(element.get("name") or "", element.get("id") or "")
                    body = etree.tostring(definition, encoding="unicode")
                    bound.setdefault(
                        label, Bound("intermediateCatchEvent", body=body, origin=origin)
                    )
    return bound, events


def _data_objects(process: etree._Element) -> dict[str, list[tuple[str, str]]]:
    """A data object reference's id -> the XML of it and of its data object."""
    objects = {o.get("id"): o for o in process.iter(f"{{{BPMN}}}dataObject")}
    found = {}
    for reference in process.iter(f"{{{BPMN}}}dataObjectReference"):
        parts = [(reference.get("id"), _text(reference))]
        target = objects.get(reference.get("dataObjectRef"))
        if target is not None:
            parts.append((target.get("id"), _text(target)))
        found[reference.get("id")] = parts
    return found


def _text(element: etree._Element) -> str:
    """The element as XML; its data associations without their ids, which a copy of the
    element made twice would give twice."""
    copied = copy.deepcopy(element)
    for inner in copied.iter():
        if _local(inner) in _ASSOCIATIONS:
            inner.attrib.pop("id", None)
    return etree.tostring(copied, encoding="unicode", with_tail=False)


def _referenced(element: etree._Element, data: dict[str, list[tuple[str, str]]]) -> tuple:
    """The data objects ``element``'s associations name."""
    found = []
    for association in element:
        if _local(association) not in _ASSOCIATIONS:
            continue
        for ref in association:
            for part in data.get((ref.text or "").strip(), []):
                if part not in found:
                    found.append(part)
    return tuple(found)


def _activity(
    element: etree._Element, kind: str, data: dict[str, list[tuple[str, str]]], origin: str
) -> Bound:
    attributes = tuple(
        (key, value)
        for key, value in element.attrib.items()
        if key in ("calledElement", "scriptFormat")
    )
    body = "".join(
        ONE_INSTANCE if _local(child) == "multiInstanceLoopCharacteristics" else _text(child)
        for child in element
        if _local(child) not in _GRAPH
    )
    return Bound(kind, attributes, body, _referenced(element, data), origin)


def _signal(element: etree._Element, data: dict[str, list[tuple[str, str]]], origin: str) -> Bound:
    """A signal event's message type, payload and QoS (its extension elements) and the data
    objects its message fills or its payload reads."""
    body = "".join(
        _text(child)
        for child in element
        if _local(child) == "extensionElements" or _local(child) in _ASSOCIATIONS
    )
    return Bound("signal", (), body, _referenced(element, data), origin)
