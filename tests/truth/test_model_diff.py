"""``robotale discover diff`` on a generated mission: the driving model against the model
discovered from its runs. The workers' battery handlers are a branch the runs never take (only
the scout's battery is made to drain fast); what the robots never used is counted here from the
driving model's XML (lxml) and the log's activities, apart from robotale's diff."""

from __future__ import annotations

import json
import re
import warnings
from pathlib import Path

import pytest
from conftest import simulate_generated
from lxml import etree

from robotale.cli import main
from robotale.discovery.bpmn_writer import write_bpmn
from robotale.discovery.collaboration import discover_collaboration
from robotale.discovery.filters import LogFilter

BPMN = "{http://www.omg.org/spec/BPMN/20100524/MODEL}"
BIOC = "{http://bpmn.io/schema/bpmn/biocolor/1.0}"
#: a mission with a scout whose battery runs low and two workers whose batteries do not
SEED = 1


def _plain(name: str) -> str:
    return re.sub(r"[^0-9a-z]", "", name.lower())


@pytest.fixture(scope="module")
def mission(tmp_path_factory):
    folder = tmp_path_factory.mktemp("diff")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        simulated = simulate_generated(SEED, folder, runs=2)
    discovered = folder / "discovered.bpmn"
    discovered.write_text(write_bpmn(discover_collaboration(simulated.log, LogFilter())))
    return simulated, discovered


def _named_without_signal(tree) -> dict[str, dict[str, str]]:
    """Per pool: the named activities and events, less signal events and event
    sub-processes (label -> id), read straight from the XML."""
    processes = {p.get("id"): p for p in tree.iter(f"{BPMN}process")}
    found = {}
    for participant in tree.iter(f"{BPMN}participant"):
        named = {}
        for element in processes[participant.get("processRef")].iter():
            tag = element.tag if isinstance(element.tag, str) else ""
            kind = tag.removeprefix(BPMN)
            flow_node = kind.endswith(("Task", "Event")) or kind in ("callActivity", "subProcess")
            if not tag.startswith(BPMN) or not flow_node or not element.get("name"):
                continue
            if element.find(f"{BPMN}signalEventDefinition") is not None:
                continue
            if element.get("triggeredByEvent") == "true":
                continue
            named[_plain(element.get("name"))] = element.get("id")
        found[participant.get("name")] = named
    return found


def _never_done(model: Path, log) -> set[tuple[str, str]]:
    """(pool, label) of the model's named elements no robot of the pool's type did."""
    named = _named_without_signal(etree.parse(str(model)))
    done = log.groupby("robot_type")["concept:name"].agg(lambda a: {_plain(x) for x in a})
    return {
        (pool, key)
        for pool, labels in named.items()
        for key in labels
        if key not in done.get(pool, set())
    }


def _unused(found: dict) -> set[tuple[str, str]]:
    # the signal events (labelled throw:/catch:) are checked by the next test
    return {(r["pool"], r["label"]) for r in found["unused_elements"] if ":" not in r["label"]}


def test_diff_names_the_branch_the_robots_never_took(mission, tmp_path, capsys):
    simulated, discovered = mission
    data = tmp_path / "diff.json"
    model = simulated.mission.model
    assert main(["discover", "diff", str(model), str(discovered), "--json", str(data)]) == 0
    printed = capsys.readouterr().out
    said = _unused(json.loads(data.read_text(encoding="utf-8")))
    assert said == _never_done(model, simulated.log)
    # the known branch: no worker ran low, so each worker's handler went unused
    workers = [pool for pool in simulated.mission.pools if pool.startswith("Worker")]
    types = simulated.log.loc[simulated.log["robot_type"].isin(workers), "concept:name"]
    assert workers and "low_battery" not in set(types)
    for worker in workers:
        assert {(worker, "lowbattery"), (worker, "returntobase")} <= said
    assert f"{workers[0]}: low_battery" in printed
    # the generated model has no diagram: the marks cannot be drawn, and nothing is written
    out = tmp_path / "marked.bpmn"
    assert main(["discover", "diff", str(model), str(discovered), "--out", str(out)]) == 1
    assert "has no diagram" in capsys.readouterr().err and not out.exists()


def test_the_marked_model_draws_what_was_never_used(tmp_path, capsys):
    """The agri scenario's model (it has a diagram) against two runs of it."""
    from discovered_agri import agri_discovered

    model, discovered, log = agri_discovered(tmp_path)
    out, data = tmp_path / "marked.bpmn", tmp_path / "diff.json"
    assert main(["discover", "diff", str(model), str(discovered),
                 "--json", str(data), "--out", str(out)]) == 0  # fmt: skip
    found = json.loads(data.read_text(encoding="utf-8"))
    expected = _never_done(model, log)
    assert expected and _unused(found) == expected
    marked = etree.parse(str(out))
    red = {
        shape.get("bpmnElement")
        for shape in marked.iter("{http://www.omg.org/spec/BPMN/20100524/DI}BPMNShape")
        if shape.get(f"{BIOC}stroke")
    }
    named = _named_without_signal(etree.parse(str(model)))
    assert {named[pool][key] for pool, key in expected} <= red
    assert red == {i for row in found["unused_elements"] for i in row["ids"]}
    # the tractors cut grass exactly after a closest_tractor naming them (counted with
    # pandas), as the driving model's condition has it: the discovered choice reads so too
    starts = log[log["lifecycle:transition"] == "start"]
    names = starts["concept:name"]
    got = starts[(names == "closest_tractor?") & (starts["robot_type"] == "Tractor")]
    mine = got[
        [json.loads(p)["data"] == r for p, r in zip(got["msg_payload"], got["robot"], strict=True)]
    ]
    cut = starts[names == "cut_grass"]
    assert mine.groupby("robot").size().to_dict() == cut.groupby("robot").size().to_dict()
    flows = {
        f.findtext(f"{BPMN}conditionExpression"): f.get("targetRef")
        for f in etree.parse(str(discovered)).iter(f"{BPMN}sequenceFlow")
    }
    target = flows["closest_tractor.get('data') == robot.name"]
    assert "closest_tractor.get('data') != robot.name" in flows
    assert etree.parse(str(discovered)).find(f".//*[@id='{target}']").get("name") == "Cut Grass"


def test_diff_names_signals_thrown_but_never_caught(mission):
    """In the discovered model, against the log's messages: the types sent and never
    received."""
    from robotale.discovery.model_diff import diff_models

    simulated, discovered = mission
    names = simulated.log["concept:name"].astype(str)
    sent = {n[:-1] for n in names if n.endswith("!")}
    received = {n[:-1] for n in names if n.endswith("?")}
    found = diff_models(simulated.mission.model, discovered)
    assert found.uncaught_signals == sorted(_plain(t) for t in sent - received)
    # and a signal dropped from the discovered model's catches is reported
    tree = etree.parse(str(discovered))
    catch = next(tree.iter(f"{BPMN}intermediateCatchEvent", f"{BPMN}startEvent"))
    for element in list(tree.iter(f"{BPMN}intermediateCatchEvent", f"{BPMN}startEvent")):
        definition = element.find(f"{BPMN}signalEventDefinition")
        if definition is not None:
            catch = element
            break
    signal = catch.find(f"{BPMN}signalEventDefinition").get("signalRef")
    for element in list(tree.iter(f"{BPMN}intermediateCatchEvent", f"{BPMN}startEvent")):
        definition = element.find(f"{BPMN}signalEventDefinition")
        if definition is not None and definition.get("signalRef") == signal:
            element.remove(definition)
    changed = Path(discovered).with_name("uncaught.bpmn")
    tree.write(str(changed))
    name = next(s.get("name") for s in tree.iter(f"{BPMN}signal") if s.get("id") == signal)
    assert _plain(name) in diff_models(simulated.mission.model, changed).uncaught_signals


def test_diff_refuses_what_is_not_bpmn(tmp_path, capsys):
    text = tmp_path / "notes.bpmn"
    text.write_text("<notes/>")
    assert main(["discover", "diff", str(text), str(text)]) == 1
    assert capsys.readouterr().err.strip() == (
        f"robotale: {text}: not a BPMN file (its root element is not definitions)."
    )
