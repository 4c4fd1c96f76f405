"""Closing the loop: a generated mission's log -> ``discover bpmn --bind`` -> ``fame check`` ->
the discovered model simulated in the mission's own world -> its runs against the original's.

The coverage measure: per robot type, the original runs' variants (a robot's activity starts
in a run, in order, counted with pandas) that together cover at least 80 % of its cases,
most frequent first, must each appear among the variants of the discovered model's runs.
Where a mission cannot be closed the test says which robot type and why (:data:`UNCLOSED`),
and checks the reason holds, rather than skipping.
"""

from __future__ import annotations

import sys
import warnings
from pathlib import Path

import pandas as pd
import pytest
from compare import prepared
from conftest import simulate_generated
from lxml import etree

from robotale.discovery.binding import bind
from robotale.discovery.bpmn_writer import lacking_skills, write_bpmn
from robotale.discovery.collaboration import discover_collaboration
from robotale.discovery.signal_starts import started_on_signals
from robotale.fame_runtime.check import check
from robotale.fame_runtime.labels import activity_label
from robotale.fame_runtime.parser import parse_all
from robotale.sim.batch import simulate_batch
from robotale.sim.plans import plans
from robotale.sim.skills import SKILLS
from robotale.sim.worldspec import load_world

sys.path.insert(0, str(Path(__file__).parents[1] / "discovery"))
from collaboration_checks import missing_skills

B = "{http://www.omg.org/spec/BPMN/20100524/MODEL}"
SEED = 19  # a coordinator asking one worker, answers of the first seconds lost
RUNS, AGAIN = 3, 4
#: robot types whose top variants a discovered model cannot reproduce, and why
UNCLOSED = {
    "Coordinator": (
        "its resend loop asks again on a timeout until a counter reaches 3 and moves to the "
        "next task until a task counter reaches a bound: the log shows how often, not the "
        "counters, so the discovered model draws each choice at random"
    ),
    "Worker 1": (
        "it answers each ping of the coordinator, so its run repeats as often as the "
        "coordinator asks, which the discovered model draws at random"
    ),
}


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
    bindings = bind([p.name for p in started.pools], simulated.mission.model)
    bound = folder / "bound.bpmn"
    bound.write_text(write_bpmn(started, bindings))
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


@pytest.mark.slow
def test_simulating_the_discovered_model_covers_the_original_top_variants(loop, tmp_path):
    simulated, _, bound, _ = loop
    world = load_world(simulated.mission.world, bound)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        summary = simulate_batch(
            plans(world, "generated", runs=AGAIN, seed=2), tmp_path / "again", workers=0
        )
    assert summary["outcomes"].get("crashed", 0) == 0, summary
    again = prepared(tmp_path / "again")
    old, new = _variants(simulated.log), _variants(again)
    assert set(old.index.get_level_values(0)) == set(new.index.get_level_values(0))
    for kind in sorted(set(old.index.get_level_values(0))):
        top = _top(old.loc[kind])
        made = set(new.loc[kind])
        missing = [v for v in top if v not in made]
        if kind in UNCLOSED:
            assert missing, f"{kind} is covered now: drop it from UNCLOSED"
            continue
        # every activity the original's robots of this type did, the new ones did too
        assert {a for v in old.loc[kind] for a in v} <= {a for v in made for a in v}, kind
        assert missing == [], f"{kind}: top variants not reproduced: {missing}"
    unclosed = sorted(UNCLOSED)
    pytest.xfail(
        f"not closed for {', '.join(unclosed)}: "
        + "; ".join(f"{k}: {UNCLOSED[k]}" for k in unclosed)
    )
