"""The model that drove the robots against the model discovered from their runs.

Both are BPMN collaborations. Their pools are matched by name (the discovered pools are named
by robot type, as the driving model's pools are named by the robots' role); within a pool two
kinds of element are compared, by a label that does not depend on how a tool spells it:

- an activity (a task, a call activity, a sub-process) and a named event that is not a
  signal's (a timer, an error: the engine tags them as activities): its
  name with case, spaces and punctuation removed (``Take Off``, ``take_off`` and ``TakeOff``
  are one activity);
- a signal event: ``throw`` or ``catch`` and the signal's name (an end event or an
  intermediate throw event throws; a start, intermediate catch or boundary event catches).

Unnamed events, gateways and event sub-processes are not compared (an event sub-process is
compared through its start event and what it contains: one tool names it by its trigger,
another by what it does). A *flow* is a pair of compared elements of a pool
with a path of sequence flows between them through elements that are not compared.

The difference says which elements and flows of the driving model the robots never used (not
in the discovered model), which elements and flows the robots showed that the driving model
does not contain, and which signals were thrown but never caught (in the discovered model:
a throw with no catch of that signal in any pool). :func:`marked_model` writes the driving
model with what was never used drawn in a colour bpmn-js and Camunda Modeler draw.
"""

from __future__ import annotations

import re
from collections import defaultdict
from collections.abc import Iterable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from lxml import etree

from robotale.errors import InputError

BPMN = "http://www.omg.org/spec/BPMN/20100524/MODEL"
BPMNDI = "http://www.omg.org/spec/BPMN/20100524/DI"
#: bpmn-js's colour attributes (bpmn-js-color) and the OMG's non-normative ones
BIOC = "http://bpmn.io/schema/bpmn/biocolor/1.0"
COLOR = "http://www.omg.org/spec/BPMN/non-normative/color/1.0"
ACTIVITIES = {"task", "scriptTask", "serviceTask", "userTask", "callActivity", "subProcess",
              "sendTask", "receiveTask", "manualTask", "businessRuleTask"}  # fmt: skip
THROWS = {"endEvent", "intermediateThrowEvent"}
CATCHES = {"startEvent", "intermediateCatchEvent", "boundaryEvent"}
#: the colour of what the robots never used
UNUSED_STROKE, UNUSED_FILL = "#e53935", "#ffcdd2"


@dataclass(slots=True)
class Pool:
    """One pool's compared elements (label -> element ids) and flows (label pairs, with the
    ids of the sequence flows on their paths)."""

    name: str
    elements: dict[str, list[str]] = field(default_factory=dict)
    flows: dict[tuple[str, str], set[str]] = field(default_factory=dict)
    names: dict[str, str] = field(default_factory=dict)  # label -> a name to print


@dataclass(slots=True)
class ModelDiff:
    unused_elements: list[dict[str, Any]]
    unused_flows: list[dict[str, Any]]
    extra_elements: list[dict[str, Any]]
    extra_flows: list[dict[str, Any]]
    uncaught_signals: list[str]
    unmatched_pools: dict[str, list[str]]

    def to_dict(self) -> dict[str, Any]:
        return {
            "unused_elements": self.unused_elements,
            "unused_flows": self.unused_flows,
            "extra_elements": self.extra_elements,
            "extra_flows": self.extra_flows,
            "uncaught_signals": self.uncaught_signals,
            "unmatched_pools": self.unmatched_pools,
        }

    def text(self) -> str:
        lines = []
        for title, rows in (
            ("never used by the robots (in the driving model, not in the discovered one)",
             self.unused_elements),
            ("shown by the robots but not in the driving model", self.extra_elements),
        ):  # fmt: skip
            lines.append(f"Elements {title}: {len(rows)}")
            lines += [f"  {row['pool']}: {row['name']}" for row in rows]
        for title, rows in (
            ("never taken by the robots", self.unused_flows),
            ("taken by the robots but not in the driving model", self.extra_flows),
        ):
            lines.append(f"Flows {title}: {len(rows)}")
            lines += [f"  {row['pool']}: {row['source']} -> {row['target']}" for row in rows]
        uncaught = ", ".join(self.uncaught_signals) or "none"
        lines.append(f"Signals thrown but never caught: {uncaught}")
        for side, pools in self.unmatched_pools.items():
            if pools:
                lines.append(f"Pools only in the {side} model: {', '.join(pools)}")
        return "\n".join(lines)


def label(name: str) -> str:
    """A name as compared: letters and digits only, lower case."""
    return re.sub(r"[^0-9a-z]", "", name.lower())


def read_model(path: Path) -> etree._ElementTree:
    if not Path(path).is_file():
        raise InputError(f"{path}: there is no such file.")
    parser = etree.XMLParser(resolve_entities=False, no_network=True, remove_comments=True)
    try:
        tree = etree.parse(str(path), parser)
    except OSError as error:
        raise InputError(f"{path}: cannot read it ({error}).") from error
    except etree.XMLSyntaxError as error:
        raise InputError(f"{path}: not XML: {error.msg} (line {error.lineno}).") from error
    if tree.getroot().tag != f"{{{BPMN}}}definitions":
        raise InputError(f"{path}: not a BPMN file (its root element is not definitions).")
    return tree


def pools(tree: etree._ElementTree, path: Path) -> dict[str, Pool]:
    """The model's pools by name (a model without a collaboration: its processes by name)."""
    root = tree.getroot()
    processes = {p.get("id"): p for p in root.iter(f"{{{BPMN}}}process")}
    signals = {s.get("id"): s.get("name") or s.get("id") for s in root.iter(f"{{{BPMN}}}signal")}
    participants = [
        (p.get("name") or p.get("processRef"), processes.get(p.get("processRef")))
        for p in root.iter(f"{{{BPMN}}}participant")
    ]
    if not participants:
        participants = [(p.get("name") or p.get("id"), p) for p in processes.values()]
    found = {}
    for name, process in participants:
        if process is None:
            continue
        found[name] = _pool(name, process, signals)
    if not found:
        raise InputError(f"{path}: the model has no process to compare.")
    return found


def _pool(name: str, process: etree._Element, signals: dict[str, str]) -> Pool:
    pool = Pool(name)
    labels: dict[str, str] = {}  # element id -> label
    for element in process.iter():
        if not isinstance(element.tag, str):
            continue
        text = _element_label(element, signals)
        if text is None:
            continue
        key, shown = text
        labels[element.get("id")] = key
        pool.elements.setdefault(key, []).append(element.get("id"))
        pool.names.setdefault(key, shown)
    pool.flows = _flows(process, labels)
    return pool


def _element_label(element: etree._Element, signals: dict[str, str]) -> tuple[str, str] | None:
    kind = etree.QName(element).localname
    if etree.QName(element).namespace != BPMN:
        return None
    if kind in ACTIVITIES:
        if kind == "subProcess" and element.get("triggeredByEvent") == "true":
            return None  # compared by its trigger, its start event: tools name it apart
        name = element.get("name") or element.get("calledElement") or ""
        return (label(name), name) if label(name) else None
    if kind in THROWS or kind in CATCHES:
        signal = element.find(f"{{{BPMN}}}signalEventDefinition")
        if signal is None:  # a named timer or error event is tagged as an activity
            name = element.get("name") or ""
            return (label(name), name) if label(name) else None
        ref = signal.get("signalRef") or ""
        name = signals.get(ref, ref)
        role = "throw" if kind in THROWS else "catch"
        return f"{role}:{label(name)}", f"{role} {name}"
    return None


def _flows(process: etree._Element, labels: dict[str, str]) -> dict[tuple[str, str], set[str]]:
    """Pairs of compared elements joined by sequence flows through uncompared elements (a
    boundary event continues from its activity's path only through its own flows)."""
    outgoing: dict[str, list[tuple[str, str]]] = defaultdict(list)
    for flow in process.iter(f"{{{BPMN}}}sequenceFlow"):
        outgoing[flow.get("sourceRef")].append((flow.get("targetRef"), flow.get("id")))
    pairs: dict[tuple[str, str], set[str]] = {}
    for source, source_label in labels.items():
        # a depth-first walk to the next compared elements, remembering the flows taken
        stack = [(target, {flow}) for target, flow in outgoing.get(source, [])]
        seen: set[str] = set()
        while stack:
            node, path = stack.pop()
            if node in labels:
                pairs.setdefault((source_label, labels[node]), set()).update(path)
                continue
            if node in seen:
                continue
            seen.add(node)
            stack += [(target, path | {flow}) for target, flow in outgoing.get(node, [])]
    return pairs


def diff_models(driving: Path, discovered: Path) -> ModelDiff:
    """What the robots never used of ``driving``, what they did beyond it (``discovered``),
    and the signals thrown but never caught in ``discovered``."""
    mine, theirs = pools(read_model(driving), driving), pools(read_model(discovered), discovered)
    by_label = {label(name): name for name in theirs}
    matched = {name: by_label[label(name)] for name in mine if label(name) in by_label}
    unused_elements, unused_flows, extra_elements, extra_flows = [], [], [], []
    for name, other_name in matched.items():
        ours, other = mine[name], theirs[other_name]
        unused_elements += _elements(ours, set(ours.elements) - set(other.elements))
        extra_elements += _elements(other, set(other.elements) - set(ours.elements), name)
        unused_flows += _pairs(ours, set(ours.flows) - set(other.flows))
        extra_flows += _pairs(other, set(other.flows) - set(ours.flows), name)
    return ModelDiff(
        unused_elements,
        unused_flows,
        extra_elements,
        extra_flows,
        uncaught_signals(theirs.values()),
        {
            "driving": sorted(set(mine) - set(matched)),
            "discovered": sorted(set(theirs) - set(matched.values())),
        },
    )


def _elements(pool: Pool, keys: set[str], name: str | None = None) -> list[dict[str, Any]]:
    return [
        {"pool": name or pool.name, "label": key, "name": pool.names[key],
         "ids": pool.elements[key]}
        for key in sorted(keys)
    ]  # fmt: skip


def _pairs(pool: Pool, keys: set[tuple[str, str]], name: str | None = None) -> list[dict]:
    return [
        {"pool": name or pool.name, "source": pool.names[a], "target": pool.names[b],
         "flows": sorted(pool.flows[(a, b)])}
        for a, b in sorted(keys)
    ]  # fmt: skip


def uncaught_signals(found: Iterable[Pool]) -> list[str]:
    """The signals some pool throws and no pool catches."""
    labels = [key for pool in found for key in pool.elements]
    thrown = {key.split(":", 1)[1] for key in labels if key.startswith("throw:")}
    caught = {key.split(":", 1)[1] for key in labels if key.startswith("catch:")}
    return sorted(thrown - caught)


def marked_model(driving: Path, diff: ModelDiff) -> bytes:
    """The driving model with its never-used elements and flows drawn red (bpmn-js's
    ``bioc`` colours and the OMG's ``color`` attributes on their diagram shapes and edges);
    an InputError when the model has no diagram to draw them on."""
    tree = read_model(driving)
    if tree.getroot().find(f"{{{BPMNDI}}}BPMNDiagram") is None:
        raise InputError(
            f"{driving}: the model has no diagram (BPMNDI) to draw the marks on; --json lists "
            "the ids of the elements and flows never used."
        )
    unused = {i for row in diff.unused_elements for i in row["ids"]}
    unused |= {i for row in diff.unused_flows for i in row["flows"]}
    for shape in tree.getroot().iter(f"{{{BPMNDI}}}BPMNShape", f"{{{BPMNDI}}}BPMNEdge"):
        if shape.get("bpmnElement") in unused:
            shape.set(f"{{{BIOC}}}stroke", UNUSED_STROKE)
            shape.set(f"{{{COLOR}}}border-color", UNUSED_STROKE)
            if etree.QName(shape).localname == "BPMNShape":
                shape.set(f"{{{BIOC}}}fill", UNUSED_FILL)
                shape.set(f"{{{COLOR}}}background-color", UNUSED_FILL)
    etree.cleanup_namespaces(tree, top_nsmap={"bioc": BIOC, "color": COLOR})
    return etree.tostring(tree, xml_declaration=True, encoding="UTF-8")
