"""The physical scenario of the thesis (5.3), simulated: REX finds the target, DINGO goes
there and fires, and DINGO's ``done`` ends both robots' processes."""

from __future__ import annotations

import json
import math

from simbags import manifest, messages, record, tags


def test_rexdingo_ends_with_dingos_fire_and_both_processes_ended_by_done(rexdingo, tmp_path):
    bag = record(rexdingo, tmp_path / "runs", seed=3)
    run = manifest(bag)
    assert run["outcome"]["status"] == "ended"
    assert run["instances"] == {
        "rex": {"completed": 1, "running": False},
        "dingo": {"completed": 1, "running": False},
    }
    everything = tags(bag)
    dingo = [(t.activity, t.lifecycle) for t in everything if t.robot == "dingo"]
    assert dingo == [
        ("target_found?", "start"),
        ("target_found?", "complete"),
        ("go_to", "start"),
        ("go_to", "complete"),
        ("fire", "start"),
        ("fire", "complete"),
        ("done!", "start"),
        ("done!", "complete"),
    ]
    rex = [t for t in everything if t.robot == "rex"]
    assert [(t.activity, t.lifecycle) for t in rex] == [
        ("explore", "start"),
        ("explore", "complete"),
        ("target_found!", "start"),
        ("target_found!", "complete"),
        ("done?", "start"),
        ("done?", "complete"),
    ]
    done_sent = next(t for t in everything if t.activity == "done!")
    assert rex[-1].msg_id == done_sent.msg_id and json.loads(rex[-1].payload) == {"data": True}

    # REX reported where the target is, DINGO fired within reach of it and it was destroyed
    (target,) = run["objects"]
    found = json.loads(rex[2].payload)
    assert math.hypot(found["x"] - target["x"], found["y"] - target["y"]) < 1e-3
    assert (target["state"], target["done_by"]) == ("destroyed", "dingo")
    leds = [m for _, _, m in messages(bag, {"/dingo/led"})]
    assert [(m.r, m.g, m.b) for m in leds] == [(1.0, 0.0, 0.0), (0.0, 0.0, 0.0)]
    fire_start = next(t for t in everything if t.activity == "fire")
    odom = next(
        m.pose.pose.position
        for _, stamp, m in messages(bag, {"/dingo/odom"})
        if stamp >= fire_start.stamp.sec * 1e9 + fire_start.stamp.nanosec
    )
    assert math.hypot(odom.x - target["x"], odom.y - target["y"]) <= 0.6 + 0.05
