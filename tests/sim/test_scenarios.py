"""The shipped scenarios are BPMN collaborations the engine runs and bpmn.io draws: every
element has its shape, every flow its edge from border to border, everything inside its pool,
and they use what the FAME guidelines prescribe."""

from __future__ import annotations

import itertools
from collections import Counter

import pytest
from lxml import etree

from robotale.fame_runtime.check import check
from robotale.fame_runtime.parser import parse
from robotale.sim import scenarios
from robotale.sim.skills import SKILLS

NS = {
    "bpmn": "http://www.omg.org/spec/BPMN/20100524/MODEL",
    "bpmndi": "http://www.omg.org/spec/BPMN/20100524/DI",
    "dc": "http://www.omg.org/spec/DD/20100524/DC",
    "di": "http://www.omg.org/spec/DD/20100524/DI",
}
NODES = [
    "startEvent",
    "endEvent",
    "intermediateThrowEvent",
    "intermediateCatchEvent",
    "boundaryEvent",
    "task",
    "scriptTask",
    "callActivity",
    "subProcess",
    "exclusiveGateway",
    "eventBasedGateway",
    "parallelGateway",
    "inclusiveGateway",
    "dataObjectReference",
]
SCENARIOS = ["agri", "rexdingo"]


def model(name: str):
    return etree.parse(str(scenarios.FOLDER / f"{name}.bpmn")).getroot()


def bounds(root) -> dict[str, tuple[float, float, float, float]]:
    found = {}
    for shape in root.iterfind(".//bpmndi:BPMNShape", NS):
        box = shape.find("dc:Bounds", NS)
        found[shape.get("bpmnElement")] = tuple(
            float(box.get(k)) for k in ("x", "y", "width", "height")
        )
    return found


def inside(inner, outer, slack=0.0) -> bool:
    x, y, w, h = inner
    X, Y, W, H = outer
    return X - slack <= x and Y - slack <= y and x + w <= X + W + slack and y + h <= Y + H + slack


def on_border(point, box, slack=1.5) -> bool:
    x, y, w, h = box
    px, py = point
    if not inside((px, py, 0, 0), box, slack):
        return False
    return min(abs(px - x), abs(px - x - w), abs(py - y), abs(py - y - h)) <= slack


@pytest.mark.parametrize("name", SCENARIOS)
def test_every_element_has_a_shape_inside_its_pool_and_every_flow_an_edge(name):
    root = model(name)
    boxes = bounds(root)
    plane = root.find(".//bpmndi:BPMNPlane", NS)
    assert plane.get("bpmnElement") == root.find("bpmn:collaboration", NS).get("id")
    for participant in root.iterfind(".//bpmn:participant", NS):
        pool = boxes[participant.get("id")]
        process = root.find(f"bpmn:process[@id='{participant.get('processRef')}']", NS)
        for kind in NODES:
            for node in process.iterfind(f".//bpmn:{kind}", NS):
                assert node.get("id") in boxes, f"{node.get('id')} has no shape"
                box = boxes[node.get("id")]
                assert box[2] > 0 and box[3] > 0
                assert inside(box, pool), (
                    f"{node.get('id')} lies outside pool {participant.get('name')}"
                )
                parent = node.getparent()
                if parent.tag == f"{{{NS['bpmn']}}}subProcess":
                    assert inside(box, boxes[parent.get("id")]), (
                        f"{node.get('id')} leaves its sub-process"
                    )
    edges = {e.get("bpmnElement"): e for e in root.iterfind(".//bpmndi:BPMNEdge", NS)}
    for flow in root.iterfind(".//bpmn:sequenceFlow", NS):
        points = [
            (float(p.get("x")), float(p.get("y")))
            for p in edges[flow.get("id")].iterfind("di:waypoint", NS)
        ]
        assert len(points) >= 2
        assert on_border(points[0], boxes[flow.get("sourceRef")]), flow.get("id")
        assert on_border(points[-1], boxes[flow.get("targetRef")]), flow.get("id")
        for a, b in itertools.pairwise(points):
            assert a[0] == b[0] or a[1] == b[1], f"{flow.get('id')} is not drawn orthogonally"
    for association in root.iterfind(".//bpmn:dataInputAssociation", NS):
        assert association.get("id") in edges
    for association in root.iterfind(".//bpmn:dataOutputAssociation", NS):
        assert association.get("id") in edges


@pytest.mark.parametrize("name", SCENARIOS)
def test_no_two_shapes_of_one_scope_overlap(name):
    root = model(name)
    boxes = bounds(root)
    for scope in [*root.iterfind("bpmn:process", NS), *root.iterfind(".//bpmn:subProcess", NS)]:
        ids = [c.get("id") for c in scope if etree.QName(c).localname in NODES]
        for i, a in enumerate(ids):
            for b in ids[i + 1 :]:
                (ax, ay, aw, ah), (bx, by, bw, bh) = boxes[a], boxes[b]
                apart = ax + aw <= bx or bx + bw <= ax or ay + ah <= by or by + bh <= ay
                assert apart, f"{a} and {b} overlap"


@pytest.mark.parametrize("name", SCENARIOS)
def test_the_engine_runs_them_and_every_signal_pair_is_qos_compatible(name):
    report = check(parse(scenarios.FOLDER / f"{name}.bpmn"), skills=SKILLS)
    assert report.problems == []
    assert report.pairs and all(pair.compatible for pair in report.pairs)


def test_agri_uses_what_the_guidelines_prescribe():
    root = model("agri")
    kinds = Counter(etree.QName(e).localname for e in root.iter() if isinstance(e.tag, str))
    tractor = root.find("bpmn:collaboration/bpmn:participant[@name='Tractor']", NS)
    assert tractor.find("bpmn:participantMultiplicity", NS) is not None  # G1.2
    called = Counter(c.get("calledElement") for c in root.iterfind(".//bpmn:callActivity", NS))
    assert called["GoTo"] >= 3  # G2.1.1: a building block reused
    scripts = root.findall(".//bpmn:scriptTask", NS)
    assert scripts and all(s.get("scriptFormat") == "python" for s in scripts)  # G2.1.2
    handlers = root.findall(".//bpmn:subProcess[@triggeredByEvent='true']", NS)
    assert {h.get("name") for h in handlers} == {
        "Weed Found",
        "End Handler",
        "Low Battery Handler",
    }  # G2.2
    assert kinds["eventBasedGateway"] == 2 and kinds["exclusiveGateway"] >= 3  # G2.4, G2.5
    assert kinds["signalEventDefinition"] == 9  # G3: five signals, thrown and caught
    assert kinds["errorEventDefinition"] == 2  # G4: low_battery, drone and tractors
    timers = {t.text for t in root.iterfind(".//bpmn:timeDuration", NS)}
    assert timers == {"PT10S", "PT30S"}  # G5
    conditions = [c.text for c in root.iterfind(".//bpmn:condition", NS)]
    assert any("battery" in c and "0.99" in c for c in conditions)  # G6: battery_full
    assert kinds["dataObjectReference"] >= 8  # G7
