"""Closing the loop: a generated mission's log -> ``discover bpmn --bind`` -> ``fame check`` ->
the discovered model simulated in the mission's own world -> its runs against the original's.

The coverage measure: per robot type, the original runs' variants (a robot's activity starts
in a run, in order, counted with pandas) that together cover at least 80 % of its cases,
most frequent first, must each appear among the variants of the discovered model's runs.
The discovered model's runs are projected onto the original's activities (the engine tags
each event sub-process itself, where the driving model had a boundary event). Mission 19's
coordinator asks, waits for the answer or its timeout, and asks again or takes the next task
on counters the log does not record: it closes because a throw and the wait that always
follows it are mined as one step, and a loop that always went round the same number of times
is written out so.
"""

from __future__ import annotations

import json
import random
import sys
import warnings
from pathlib import Path

import pandas as pd
import pytest
from compare import prepared
from conftest import simulate_generated
from lxml import etree

from robotale.cli import main
from robotale.discovery.binding import bind
from robotale.discovery.bpmn_writer import lacking_skills, write_bpmn
from robotale.discovery.collaboration import discover_collaboration
from robotale.discovery.layout import Operator, leaves
from robotale.discovery.repeats import constant_repeats
from robotale.discovery.signal_starts import started_on_signals
from robotale.discovery.trigger_times import timed_triggers
from robotale.fame_runtime.check import check
from robotale.fame_runtime.labels import activity_label
from robotale.fame_runtime.parser import parse_all
from robotale.sim.batch import simulate_batch
from robotale.sim.plans import plans, resolve_world
from robotale.sim.skills import SKILLS
from robotale.sim.worldspec import load_world

sys.path.insert(0, str(Path(__file__).parents[1] / "discovery"))
from collaboration_checks import missing_skills

B = "{http://www.omg.org/spec/BPMN/20100524/MODEL}"
SEED = 19  # a coordinator asking one worker, answers of the first seconds lost
RUNS, AGAIN = 3, 6
#: missions whose discovered model reproduces the original's top variants: a scout whose
#: exploration a timer cuts short, one or two workers, one of which gives up driving (mission
#: 19, a coordinator that asks again until its worker answers, is the module's own fixture);
#: mission 14, which the docs name closed too
CLOSED = (2, 14, 20)


def discovered(simulated, folder: Path) -> Path:
    """The model ``discover bpmn --bind`` writes for the simulated mission's log."""
    return bound_model(simulated.log, simulated.mission.model, folder)


def bound_model(log: pd.DataFrame, driving: Path, folder: Path) -> Path:
    collaboration = started_on_signals(discover_collaboration(log), log)
    bindings = bind([p.name for p in collaboration.pools], driving)
    bindings.timers = timed_triggers(collaboration, log, bindings)
    bindings.repeats = constant_repeats(collaboration, log)
    out = folder / "bound.bpmn"
    out.write_text(write_bpmn(collaboration, bindings))
    return out


@pytest.fixture(scope="module")
def loop(tmp_path_factory):
    folder = tmp_path_factory.mktemp("loop")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        simulated = simulate_generated(SEED, folder, runs=RUNS)
    collaboration = discover_collaboration(simulated.log)
    plain = folder / "plain.bpmn"
    plain.write_text(write_bpmn(collaboration))
    started = started_on_signals(collaboration, simulated.log)
    bound = bound_model(simulated.log, simulated.mission.model, folder)
    return (
        simulated,
        plain,
        bound,
        lacking_skills(collaboration, bind([p.name for p in started.pools])),
    )


def test_without_a_driving_model_fame_check_names_only_the_skills_the_simulation_lacks(loop):
    simulated, plain, _, sentences = loop
    # the truth: the driving model's elements the simulator has no skill for, which the log
    # tags as activities (script tasks, timers), by their tag name
    root = etree.parse(str(simulated.mission.model)).getroot()
    tagged = set(simulated.log["concept:name"].astype(str))
    scripted = {
        activity_label(e.get("name"), e.get("id"))
        for kind in ("scriptTask", "intermediateCatchEvent")
        for e in root.iter(f"{B}{kind}")
        if e.find(f"{B}signalEventDefinition") is None
    } & tagged
    expected = {"".join(w.title() for w in label.split("_")) for label in scripted}
    assert missing_skills(plain) == expected
    assert expected and not expected & set(SKILLS)
    report = check(parse_all(plain), skills=set(SKILLS))
    others = [p.sentence for _, p in report.found if "which is no skill" not in p.sentence]
    assert others == []
    # the command's own sentences: one per lacking skill
    named = {s.split("calls the skill ")[1].split(",")[0] for s in sentences}
    assert named == expected and len(sentences) == len(expected)


def test_bound_to_the_driving_model_fame_check_accepts_it(loop):
    _, _, bound, _ = loop
    report = check(parse_all(bound), skills=set(SKILLS))
    assert [p.sentence for _, p in report.found] == []
    assert report.ok
    root = etree.parse(str(bound)).getroot()
    # the worker waits for orders: a process started on ping, as the driving one
    starts = [
        e.get("name")
        for e in root.iter(f"{B}startEvent")
        if e.find(f"{B}signalEventDefinition") is not None
    ]
    assert "ping" in starts


def _variants(log: pd.DataFrame) -> pd.Series:
    """(robot type, case, robot) -> the robot's activity starts in order."""
    starts = log[log["lifecycle:transition"] == "start"]
    starts = starts.sort_values(["case:concept:name", "robot", "time:timestamp"], kind="stable")
    keys = ["robot_type", "case:concept:name", "robot"]
    return starts.groupby(keys)["concept:name"].agg(lambda names: tuple(names.astype(str)))


def _top(variants: pd.Series, share: float = 0.8) -> list[tuple[str, ...]]:
    counts = variants.value_counts()
    covered = counts.cumsum() / counts.sum()
    return list(counts.index[: int((covered < share).sum()) + 1])


def _covered(simulated, bound: Path, folder: Path) -> dict[str, list[tuple[str, ...]]]:
    """Per robot type, the original's top variants the discovered model's runs lack (their
    variants projected onto the original's activities: the engine tags each event
    sub-process itself, which a boundary event of the driving model was not)."""
    world = load_world(simulated.mission.world, bound)
    random.seed(simulated.seed)  # the model's choices draw from Python's random
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        summary = simulate_batch(
            plans(world, "generated", runs=AGAIN, seed=simulated.seed), folder / "again", workers=0
        )
    assert summary["outcomes"].get("crashed", 0) == 0, summary
    again = prepared(folder / "again")
    known = set(simulated.log["concept:name"].astype(str))
    again = again[again["concept:name"].astype(str).isin(known)]
    old, new = _variants(simulated.log), _variants(again)
    assert set(old.index.get_level_values(0)) == set(new.index.get_level_values(0))
    missing = {}
    for kind in sorted(set(old.index.get_level_values(0))):
        made = set(new.loc[kind])
        missing[kind] = [v for v in _top(old.loc[kind]) if v not in made]
    return missing


@pytest.mark.slow
@pytest.mark.parametrize("seed", CLOSED)
def test_simulating_the_discovered_model_covers_the_original_top_variants(seed, tmp_path):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        simulated = simulate_generated(seed, tmp_path, runs=RUNS)
    bound = discovered(simulated, tmp_path)
    assert check(parse_all(bound), skills=set(SKILLS)).ok
    missing = _covered(simulated, bound, tmp_path)
    assert missing and all(v == [] for v in missing.values()), missing


@pytest.mark.slow
def test_the_coordinator_waits_for_each_answer_and_its_mission_closes(loop, tmp_path):
    """The coordinator pings, then waits for the answer or its timeout; the inductive miner
    alone put the pings in parallel with the waits. Each try and each task always went round
    three times in the log (the driving model's counters), so the bound model repeats them
    so, and the mission closes."""
    simulated, _, bound, _ = loop
    # the truth, counted with pandas: whatever follows a ping of the coordinator
    starts = simulated.log[simulated.log["lifecycle:transition"] == "start"]
    starts = starts[starts["robot_type"] == "Coordinator"].sort_values(
        ["case:concept:name", "time:timestamp"], kind="stable"
    )
    names = starts["concept:name"].astype(str)
    after = names.groupby(starts["case:concept:name"]).shift(-1)[names == "ping!"]
    assert set(after) == {"pong?", "no_answer"}
    collaboration = discover_collaboration(simulated.log)
    steps = leaves(collaboration.pool("Coordinator").block)
    assert not _parallel(collaboration.pool("Coordinator").block)
    assert {steps[i + 1] for i, step in enumerate(steps) if step == "ping!"} == set(after)
    missing = _covered(simulated, bound, tmp_path)
    assert set(missing) == {"Coordinator", "Worker 1"}
    assert all(v == [] for v in missing.values()), missing


def _parallel(block) -> bool:
    return isinstance(block, Operator) and (
        block.kind == "and" or any(map(_parallel, block.children))
    )


def test_the_command_binds_to_a_driving_model(loop, tmp_path, capsys):
    simulated, _, bound, _ = loop
    csv = tmp_path / "log.csv"
    simulated.log.to_csv(csv, index=False)
    out = tmp_path / "cli.bpmn"
    args = ["discover", "bpmn", str(csv), "--out", str(out)]
    assert main([*args, "--bind", str(simulated.mission.model)]) == 0
    printed = capsys.readouterr().out
    assert "pool Worker 1 (worker_1): event sub-processes on none; an instance per ping?" in printed
    assert "which the simulation does not have" not in printed
    assert check(parse_all(out), skills=set(SKILLS)).ok

    # the same elements as the model the test's own route writes
    def kinds(path):
        root = etree.parse(str(path)).getroot()
        return sorted(
            (etree.QName(e).localname, e.get("name") or "")
            for e in root.iter()
            if e.get("name") is not None
        )

    assert kinds(out) == kinds(bound)
    missing, fresh = tmp_path / "missing.bpmn", tmp_path / "fresh.bpmn"
    assert main([*args[:3], "--out", str(fresh), "--bind", str(missing)]) == 1
    assert f"--bind {missing}: there is no such file" in capsys.readouterr().err
    assert not fresh.exists()


def test_fame_check_with_the_world_uses_the_simulation_s_skills(loop, capsys):
    simulated, plain, bound, sentences = loop
    world = str(simulated.mission.world)
    assert main(["fame", "check", str(bound), "--world", world]) == 0
    capsys.readouterr()
    assert main(["fame", "check", str(plain), "--world", world]) == 1
    problems = [line for line in capsys.readouterr().out.splitlines() if "calls '" in line]
    called = {line.split("calls '")[1].split("'")[0] for line in problems}
    assert called == missing_skills(plain) and len(called) == len(sentences)
    assert all("which is no skill" in line for line in problems)


@pytest.mark.slow
def test_the_agri_mission_runs_discovered_and_the_drone_hears_the_weeds(tmp_path):
    """agri: the drone's camera publishes ``weed_found`` while Explore runs, which the driving
    model catches with an event sub-process listening all along. The log has every receipt
    inside an Explore, so the discovered model catches it with a non-interrupting event
    sub-process too; run in the agri world, the drone hears the weeds and reports them, the
    tractors answer with their positions and the closest one moves to the weed. Whether a
    tractor cuts is no draw: the log holds the reason, the payload of the ``closest_tractor``
    a tractor caught names the tractor that is to go, and the discovered choice reads it."""
    world = resolve_world("agri")[0]
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        simulate_batch(plans(world, "agri", runs=2, seed=3), tmp_path / "runs", workers=0)
        log = prepared(tmp_path / "runs")
    bound = bound_model(log, world.model, tmp_path)
    report = check(parse_all(bound), skills=set(SKILLS))
    assert [p.sentence for _, p in report.found] == [] and report.ok, report.pairs
    root = etree.parse(str(bound)).getroot()
    listening = [
        (start.get("isInterrupting"), etree.QName(start.getparent()).localname)
        for start in root.iter(f"{B}startEvent")
        if start.get("name") == "weed_found" and start.find(f"{B}signalEventDefinition") is not None
    ]
    assert listening == [("false", "subProcess")]
    random.seed(3)  # the model's choices draw from Python's random
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        summary = simulate_batch(
            plans(load_world(world.file, bound), "agri", runs=2, seed=3),
            tmp_path / "again",
            workers=0,
        )
    assert summary["outcomes"].get("crashed", 0) == 0, summary
    again = prepared(tmp_path / "again")
    # the truth: the original runs, counted with pandas: the drone does again all it did
    # (its low-battery handler aside, which a run need not meet), the tractors answer
    drone = set(again.loc[again["robot"] == "drone", "concept:name"].astype(str))
    before = set(log.loc[log["robot"] == "drone", "concept:name"].astype(str))
    assert before - drone <= {"low_battery", "end_handler"}, before - drone
    assert {"weed_found?", "weed_position!", "closest_tractor!"} <= drone
    tractors = set(again.loc[again["robot"] != "drone", "concept:name"].astype(str))
    assert {"weed_position?", "tractor_position!", "closest_tractor?", "move"} <= tractors
    # each tractor cut grass once per closest_tractor naming it, in the discovered model's
    # runs as in the driving model's (counted with pandas)
    assert "closest_tractor.get('data') == robot.name" in bound.read_text(encoding="utf-8")
    for runs in (log, again):
        starts = runs[runs["lifecycle:transition"] == "start"]
        names = starts["concept:name"].astype(str)
        got = starts[(names == "closest_tractor?") & (starts["robot"] != "drone")]
        payloads = zip(got["msg_payload"], got["robot"], strict=True)
        mine = got[[json.loads(text)["data"] == robot for text, robot in payloads]]
        cut = starts[names == "cut_grass"]
        assert mine.groupby("robot").size().to_dict() == cut.groupby("robot").size().to_dict()
