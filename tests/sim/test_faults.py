"""Faults a user models show up in the bag as they would on real robots: a robot that dies
falls silent, a dropped message is sent but never received, an emptying battery warns and
stops the robot."""

from __future__ import annotations

from dataclasses import replace

import pytest
from simbags import manifest, messages, record, seconds, tags

from robotale.errors import InputError
from robotale.sim.faults import parse_fault
from robotale.sim.plans import adjust

ROBOTS = ["drone", "tractor_1", "tractor_2"]


def faulty(world, tmp_path, name: str, *texts: str, seed: int = 1):
    faults = tuple(parse_fault(text, ROBOTS) for text in texts)
    return record(world, tmp_path / name, seed=seed, faults=faults)


def start_of(bag) -> float:
    return tags(bag)[0].stamp.sec


def test_a_tractor_that_dies_on_its_way_falls_silent_and_leaves_its_weed(short_agri, tmp_path):
    healthy = tags(record(short_agri, tmp_path / "healthy"))
    move = next(t for t in healthy if t.activity == "move" and t.lifecycle == "start")
    begin = healthy[0].stamp.sec
    dies_at = round(seconds(move) - begin + 2.0, 1)
    bag = faulty(short_agri, tmp_path, "faulty", f"die:{move.robot}@{dies_at}")
    run = manifest(bag)
    assert run["faults"] == [
        {"fault": f"die:{move.robot}@{dies_at}", "applied": True, "at": dies_at}
    ]
    assert run["robots_final"][move.robot]["alive"] is False
    assert run["weeds"]["cut"] < run["weeds"]["total"]
    mine = [t for t in tags(bag) if t.robot == move.robot]
    assert (mine[-1].activity, mine[-1].lifecycle) == ("move", "start")  # never completed
    odom = messages(bag, {f"/{move.robot}/odom"})
    assert odom[-1][1] / 1e9 - begin <= dies_at + 1e-6
    others = messages(bag, {"/drone/odom"})
    assert others[-1][1] / 1e9 - begin > dies_at + 5  # the others go on


def test_a_dropped_message_is_sent_and_recorded_but_never_received(short_agri, tmp_path):
    one_weed = adjust(short_agri, weeds=(1, 1))
    healthy = tags(record(one_weed, tmp_path / "healthy"))
    chosen = next(t for t in healthy if t.activity == "move").robot
    bag = faulty(one_weed, tmp_path, "faulty", f"drop:/closest_tractor,to={chosen},nth=1")
    everything = tags(bag)
    sent = next(t for t in everything if t.activity == "closest_tractor!")
    receivers = {
        t.robot for t in everything if t.activity == "closest_tractor?" and t.msg_id == sent.msg_id
    }
    # the drone's Explore consumes it too (resume_on), and says so with a receive tag
    assert receivers == {"drone", *ROBOTS[1:]} - {chosen}
    recorded = messages(bag, {"/closest_tractor"})
    assert [m.data for _, _, m in recorded] == [chosen]
    # the chosen tractor waits the 30 seconds of its event-based race, and nobody cuts
    replied = next(t for t in everything if t.robot == chosen and t.activity == "tractor_position!")
    waited = [t for t in everything if t.robot == chosen and t.activity == "30_sec"]
    assert waited and seconds(waited[0]) == pytest.approx(seconds(replied) + 30.0, abs=1e-3)
    assert not [t for t in everything if t.activity in ("move", "cut_grass")]
    assert manifest(bag)["weeds"] == {"total": 1, "found": 1, "cut": 0}


def test_an_emptying_battery_warns_low_battery_and_the_drone_goes_home(short_agri, tmp_path):
    bag = faulty(short_agri, tmp_path, "faulty", "battery:drone@15,rate=0.02")
    begin = start_of(bag)
    drone = [t for t in tags(bag) if t.robot == "drone"]
    activities = [t.activity for t in drone if t.lifecycle == "start"]
    assert "low_battery" in activities and "end_handler" in activities
    # the Explore the low battery interrupted never completes (earlier ones ended on a weed)
    explores = [t.lifecycle for t in drone if t.activity == "explore"]
    assert explores.count("complete") == explores.count("start") - 1
    # caught first, then the interrupting sub-process it starts
    assert activities[activities.index("low_battery") :] == [
        "low_battery",
        "end_handler",
        "return_to_base",
        "land",
    ]
    warnings = messages(bag, {"/drone/low_battery"})
    battery = messages(bag, {"/drone/battery"})
    first_warning = warnings[0][1]
    level = next(m.percentage for _, t, m in battery if t >= first_warning)
    assert level < 0.2
    assert seconds(next(t for t in drone if t.activity == "low_battery")) - begin > 15


def test_an_empty_battery_stops_the_drone_and_the_run_meets_its_time_limit(short_agri, tmp_path):
    world = replace(short_agri, time_limit=120.0)
    bag = faulty(world, tmp_path, "faulty", "battery:drone@10,rate=0.1")
    run = manifest(bag)
    assert run["outcome"]["status"] == "time limit"
    assert run["duration"] == pytest.approx(120.0)
    assert run["robots_final"]["drone"]["battery"] == 0.0
    heights = [m.pose.pose.position.z for _, _, m in messages(bag, {"/drone/odom"})]
    assert max(heights) == pytest.approx(1.5) and heights[-1] == 0.0  # it dropped


def test_faults_vary_per_run_from_the_seed_and_bad_ones_are_refused():
    from robotale.sim.faults import plan

    fault = parse_fault("die:tractor_1@30-90,p=0.5", ROBOTS)
    plans = [plan([fault], seed)[0] for seed in range(40)]
    assert {p.applied for p in plans} == {True, False}
    assert all(30 <= p.at <= 90 for p in plans)
    assert plan([fault], 7) == plan([fault], 7)
    for text, words in [
        ("explode:drone@3", "must start with one of die:, drop:, battery:"),
        ("die:tractor_9@3", "there is no robot 'tractor_9'"),
        ("die:drone", "say when with @SECONDS"),
        ("drop:closest_tractor", "a drop names a topic"),
        ("battery:drone@10,speed=2", "'speed=2' is not one of for=..., p=..., rate=..."),
        ("die:drone@9-3", "ends before it starts"),
    ]:
        with pytest.raises(InputError, match=words):
            parse_fault(text, ROBOTS)
