"""``simulate agri --thesis``: the drone's low battery interrupts Explore, the tags say so, and
the drone's DFG must draw figure 7.4's ``explore -> low_battery`` edge."""

from __future__ import annotations

import oracle
import pytest
from compare import prepared

from robotale.discovery.dfg import discover_dfg
from robotale.sim import scenarios
from robotale.sim.batch import simulate_batch
from robotale.sim.plans import plans
from robotale.sim.worldspec import load_world

pytestmark = pytest.mark.slow


@pytest.fixture(scope="module")
def thesis_run(tmp_path_factory):
    world = load_world(scenarios.world_file("agri", "thesis"))
    out = tmp_path_factory.mktemp("thesis")
    simulate_batch(plans(world, "agri", runs=2, seed=1), out, workers=0)
    return out, prepared(out)


def test_an_explore_the_low_battery_interrupted_ends_with_ate_abort(thesis_run):
    out, log = thesis_run
    truth = [
        row
        for row in oracle.activity_instances(oracle.load_batch(out))
        if row["robot"] == "drone" and row["activity"] == "explore"
    ]
    interrupted = [
        (row["case"], round(row["end"], 3)) for row in truth if row["outcome"] == "interrupted"
    ]
    drone = log[log["robot"] == "drone"]
    aborts = drone[
        (drone["concept:name"] == "explore") & (drone["lifecycle:transition"] == "ate_abort")
    ]
    tagged = [
        (case, round(time.timestamp(), 3))
        for case, time in zip(aborts["case:concept:name"], aborts["time:timestamp"], strict=True)
    ]
    assert interrupted and tagged == interrupted
    # the low battery is what interrupted it: caught at the same instant
    lows = drone[drone["concept:name"] == "low_battery"]
    low_times = {
        (c, round(t.timestamp(), 3))
        for c, t in zip(lows["case:concept:name"], lows["time:timestamp"], strict=True)
    }
    assert set(tagged) <= low_times


def _uninterrupted_by_others(truth: list[dict], explore: dict) -> bool:
    """No other drone activity started while ``explore`` ran: what the drone did next, after
    it, is whatever interrupted it."""
    return not any(
        row is not explore
        and row["case"] == explore["case"]
        and row["robot"] == "drone"
        and explore["start"] < row["start"] < explore["end"]
        for row in truth
    )


def test_the_drone_dfg_has_figure_7_4s_explore_to_low_battery_edge(thesis_run):
    out, log = thesis_run
    graph = discover_dfg(log[log["robot"] == "drone"])
    edges = {(e.source, e.target): e.count for e in graph.edges}
    # the truth (not the tags): each Explore the low battery interrupted while the drone did
    # nothing else is directly followed by the low battery's catch, which starts the handler
    truth = oracle.activity_instances(oracle.load_batch(out))
    interrupted = [
        row
        for row in truth
        if row["robot"] == "drone" and row["activity"] == "explore"
        if row["outcome"] == "interrupted" and _uninterrupted_by_others(truth, row)
    ]
    assert interrupted
    assert edges.get(("explore", "low_battery")) == len(interrupted)
    # the catch comes before the sub-process it starts: every handler the truth ran follows it
    handlers = [row for row in truth if (row["robot"], row["activity"]) == ("drone", "end_handler")]
    assert edges.get(("low_battery", "end_handler")) == len(handlers) > 0
    assert ("explore", "end_handler") not in edges
