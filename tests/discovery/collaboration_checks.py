"""Checks on a discovered BPMN file, read back with lxml and robotale's own parser."""

from __future__ import annotations

from pathlib import Path

from lxml import etree

from robotale.fame_runtime.check import check
from robotale.fame_runtime.parser import parse_all
from robotale.sim.skills import SKILLS

B = "{http://www.omg.org/spec/BPMN/20100524/MODEL}"
DC = "{http://www.omg.org/spec/DD/20100524/DC}"


def signal_events(root, tag: str) -> set[str]:
    """The signals the ``tag`` events (intermediateThrowEvent ...) name."""
    names = {s.get("id"): s.get("name") for s in root.iter(f"{B}signal")}
    return {
        names[d.get("signalRef")]
        for event in root.iter(f"{B}{tag}")
        for d in event.iter(f"{B}signalEventDefinition")
    }


def handlers(root) -> dict[str, set[str]]:
    """Pool name -> the triggers of its event sub-processes."""
    pools = {p.get("processRef"): p.get("name") for p in root.iter(f"{B}participant")}
    errors = {e.get("id"): e.get("name") for e in root.iter(f"{B}error")}
    signals = {s.get("id"): s.get("name") for s in root.iter(f"{B}signal")}
    found: dict[str, set[str]] = {}
    for process in root.iter(f"{B}process"):
        for sub in process.iter(f"{B}subProcess"):
            if sub.get("triggeredByEvent") != "true":
                continue
            start = sub.find(f"{B}startEvent")
            error = start.find(f"{B}errorEventDefinition")
            signal = start.find(f"{B}signalEventDefinition")
            name = (
                errors[error.get("errorRef")]
                if error is not None
                else signals[signal.get("signalRef")]
            )
            found.setdefault(pools[process.get("id")], set()).add(name)
    return found


def overlaps(root) -> list[tuple[str, str]]:
    """Shapes of the diagram whose boxes intersect, pools and sub-processes apart from what
    they contain."""
    boxes = {}
    for shape in root.iter("{http://www.omg.org/spec/BPMN/20100524/DI}BPMNShape"):
        b = shape.find(f"{DC}Bounds")
        boxes[shape.get("bpmnElement")] = tuple(
            float(b.get(k)) for k in ("x", "y", "width", "height")
        )
    containers = {e.get("id") for e in root.iter(f"{B}participant", f"{B}subProcess")}
    inside = {}
    for sub in root.iter(f"{B}subProcess"):
        for child in sub:
            if child.get("id"):
                inside[child.get("id")] = sub.get("id")
    found = []
    names = sorted(boxes)
    for i, a in enumerate(names):
        for b in names[i + 1 :]:
            if a in containers and (b not in containers or a.startswith("Pool")):
                continue
            if b in containers and (a not in containers or b.startswith("Pool")):
                continue
            ax, ay, aw, ah = boxes[a]
            bx, by, bw, bh = boxes[b]
            if ax < bx + bw and bx < ax + aw and ay < by + bh and by < ay + ah:
                found.append((a, b))
    return found


def unshaped(root) -> list[str]:
    """Flow nodes and flows the diagram does not draw."""
    drawn = {
        e.get("bpmnElement")
        for e in root.iter(
            "{http://www.omg.org/spec/BPMN/20100524/DI}BPMNShape",
            "{http://www.omg.org/spec/BPMN/20100524/DI}BPMNEdge",
        )
    }
    kinds = (
        "callActivity", "startEvent", "endEvent", "intermediateThrowEvent",
        "intermediateCatchEvent", "exclusiveGateway", "parallelGateway", "inclusiveGateway",
        "subProcess", "sequenceFlow", "participant",
    )  # fmt: skip
    return [e.get("id") for k in kinds for e in root.iter(f"{B}{k}") if e.get("id") not in drawn]


def check_problems_besides_skills(path: Path) -> list[str]:
    """What ``fame check`` (with the simulator's skills) finds that is not a missing skill."""
    report = check(parse_all(path), skills=set(SKILLS))
    return [p.sentence for _, p in report.found if "which is no skill" not in p.sentence]


def missing_skills(path: Path) -> set[str]:
    report = check(parse_all(path), skills=set(SKILLS))
    return {
        p.sentence.split("calls '")[1].split("'")[0]
        for _, p in report.found
        if "no skill" in p.sentence
    }


def read(path: Path):
    return etree.parse(str(path)).getroot()
