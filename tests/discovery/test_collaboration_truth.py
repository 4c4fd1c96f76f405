"""``discover bpmn`` on runs written from a known truth (``tests/conventions.py``): each
activity's documentation gives how often it ran, by whom, and its mean and median duration as
the truth's instances have them, and a message type the drone sent that nobody received is
marked so, where the types that were received are not."""

from __future__ import annotations

import re

import numpy as np
import pandas as pd
import pytest
from collaboration_checks import overlaps, read, unshaped
from conventions import GroundTruth, Message, RunWriter, write_robotale_csv

from robotale.discovery.bpmn_writer import write_bpmn
from robotale.discovery.collaboration import discover_collaboration
from robotale.eventlog.readers import read_log

B = "{http://www.omg.org/spec/BPMN/20100524/MODEL}"
ROBOTS = {"drone": "Drone", "tractor_1": "Tractor", "tractor_2": "Tractor"}
DOCUMENTED = ("callActivity", "intermediateThrowEvent", "intermediateCatchEvent")


def _truth(runs: int = 6) -> GroundTruth:
    """The drone takes off, explores, sends each tractor a weed position (the second one
    lost in odd runs) and a status nobody listens to, and lands; the tractors move. Durations
    drawn at random, in eighths of a second (exact in the CSV's milliseconds)."""
    rng = np.random.default_rng(7)

    def tick(low: float, high: float) -> float:
        return round(rng.uniform(low, high) * 8) / 8

    truth = GroundTruth(cases=[f"run{n}" for n in range(runs)], robots=dict(ROBOTS))
    for n, case in enumerate(truth.cases):
        run = RunWriter(truth, case, pd.Timestamp("2024-05-01T08:00:00Z") + pd.Timedelta(hours=n))
        run.instance("drone", "takeoff", 0, tick(2, 5))
        run.instance("drone", "explore", 6, 6 + tick(20, 30))
        run.message(1, "tractor_1", 10, 10 + tick(1, 2))
        run.message(2, "tractor_2", 15, None if n % 2 else 15 + tick(1, 2))
        run.instance("tractor_1", "move", 20, 20 + tick(5, 15))
        run.instance("tractor_2", "move", 21, 21 + tick(5, 15))
        status = f"{case}-s"
        truth.messages.append(Message(case, status, "status", "drone", "base", run.at(40), None))
        run.instance("drone", "status!", 40, 40.5, status)
        run.instance("drone", "land", 45, 45 + tick(2, 5))
    return truth


def _documented(root) -> dict[tuple[str, str], str]:
    """(pool, element name) -> its documentation, for activities and signal events."""
    processes = {p.get("processRef"): p.get("name") for p in root.iter(f"{B}participant")}
    found = {}
    for process in root.iter(f"{B}process"):
        for kind in DOCUMENTED:
            for element in process.iter(f"{B}{kind}"):
                key = (processes[process.get("id")], f"{kind}:{element.get('name')}")
                found[key] = element.findtext(f"{B}documentation")
    return found


def test_documentation_and_signals_are_the_truths(tmp_path):
    truth = _truth()
    log = read_log(write_robotale_csv(truth, tmp_path / "runs.csv"))
    root = read_text(write_bpmn(discover_collaboration(log)), tmp_path)
    documented = _documented(root)
    instances = truth.instance_table().assign(pool=lambda t: t["robot"].map(ROBOTS))
    stats = instances.groupby(["pool", "activity"])
    expected = {}
    for (pool, activity), own in stats:
        if activity.endswith(("!", "?")):
            kind = "intermediateThrowEvent" if activity.endswith("!") else "intermediateCatchEvent"
            key = (pool, f"{kind}:{activity[:-1]}")
        else:
            key = (pool, f"callActivity:{activity.replace('_', ' ').title()}")
        robots = ", ".join(sorted(own["robot"].unique()))
        expected[key] = (
            f"{len(own)} times by {robots}; duration mean {own['seconds'].mean():.3f} s, "
            f"median {own['seconds'].median():.3f} s"
        )
    assert set(documented) == set(expected)
    for key, text in expected.items():
        assert documented[key].split(". Signal ")[0] == text, key
    # the signals: counted from the truth's messages
    messages = pd.DataFrame([m.__dict__ for m in truth.messages])
    for topic, own in messages.groupby("topic"):
        received = int(own["received"].notna().sum())
        said = [t for (_, name), t in documented.items() if name.endswith(f":{topic}")]
        assert said and all(f"Signal {topic}: sent {len(own)} times by Drone" in t for t in said)
        if received:
            assert all(f"received {received} times by Tractor" in t for t in said)
        else:
            assert all(t.endswith("never received") for t in said)
    never = [name for (_, name), t in documented.items() if t.endswith("never received")]
    assert never == ["intermediateThrowEvent:status"]


def read_text(text: str, folder):
    path = folder / "discovered.bpmn"
    path.write_text(text, encoding="utf-8")
    return read(path)


def test_no_pool_for_a_receiver_outside_the_log(tmp_path):
    """The status was addressed to a base station that is no robot of the log: no pool."""
    log = read_log(write_robotale_csv(_truth(2), tmp_path / "runs.csv"))
    names = [p.name for p in discover_collaboration(log).pools]
    assert sorted(names) == ["Drone", "Tractor"]
    assert not [n for n in names if re.search("base", n, re.I)]


def _positions(root) -> dict[str, tuple[float, float]]:
    """Element name -> the top left corner of its shape."""
    names = {e.get("id"): e.get("name") for e in root.iter() if e.get("name")}
    corners = {}
    for shape in root.iter("{http://www.omg.org/spec/BPMN/20100524/DI}BPMNShape"):
        bounds = shape.find("{http://www.omg.org/spec/DD/20100524/DC}Bounds")
        name = names.get(shape.get("bpmnElement"))
        if name:
            corners[name] = (float(bounds.get("x")), float(bounds.get("y")))
    return corners


def _shape(block) -> str:
    """A mined block as text: ``seq(xor(a, b), ...)``, children in their order."""
    from robotale.discovery.layout import Operator

    if isinstance(block, Operator):
        return f"{block.kind}({', '.join(_shape(child) for child in block.children)})"
    return block.label


def test_choices_parallel_steps_and_loops_become_gateways(tmp_path):
    """Runs of a known process: a choice of scan or photo, drive and arm in either order
    (drive first twice as often), cut repeated with a turn between, park. The discovered
    process is that process, its gateways exclusive for the choice and the loop and
    parallel for drive and arm: not two interruptions, which each of them, once per run and
    following its predecessor less than half of the time, could pass for. Replaying the
    runs on it is exact: fitness 1, and precision that of pm4py on the process's own
    net."""
    import itertools

    import pm4py

    from robotale.discovery.conformance import check_conformance

    traces = [
        [first, *pair, *["cut", "turn"] * turns, "cut", "park"]
        for first, pair, turns in itertools.product(
            ("scan", "photo"), (("drive", "arm"), ("drive", "arm"), ("arm", "drive")), range(3)
        )
    ]
    t0 = pd.Timestamp("2024-01-01", tz="UTC")
    log = pd.DataFrame(
        [
            (str(n), step, t0 + pd.Timedelta(hours=n, seconds=i), "rover")
            for n, trace in enumerate(traces)
            for i, step in enumerate(trace)
        ],
        columns=["case:concept:name", "concept:name", "time:timestamp", "robot"],
    )
    collaboration = discover_collaboration(log)
    (pool,) = collaboration.pools
    assert pool.handlers == []
    assert _shape(pool.block) == "seq(xor(scan, photo), and(drive, arm), loop(cut, turn), park)"
    root = read_text(write_bpmn(collaboration), tmp_path)
    gateways = {
        kind: len(list(root.iter(f"{B}{kind}"))) for kind in ("exclusiveGateway", "parallelGateway")
    }
    assert gateways == {"exclusiveGateway": 4, "parallelGateway": 2}
    # drawn left to right in the order the robot did them; a choice's and a parallel
    # block's branches one below the other, the loop's redo part below its body
    at = _positions(root)
    assert at["Scan"][0] == at["Photo"][0] < at["Drive"][0] == at["Arm"][0] < at["Cut"][0]
    assert at["Cut"][0] < at["Park"][0] and at["Turn"][1] > at["Cut"][1]
    assert at["Scan"][1] != at["Photo"][1] and at["Drive"][1] != at["Arm"][1]
    assert overlaps(root) == [] and unshaped(root) == []
    robots = check_conformance(log, tmp_path / "discovered.bpmn").robots
    tree = pm4py.parse_process_tree(
        "->(X('scan', 'photo'), +('drive', 'arm'), *('cut', 'turn'), 'park')"
    )
    exact = pm4py.precision_token_based_replay(log, *pm4py.convert_to_petri_net(tree))
    assert robots["fitness"].tolist() == [1.0]
    assert robots["precision"].tolist() == [pytest.approx(exact)]
