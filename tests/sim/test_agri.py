"""The running scenario of the thesis, simulated: the tags a short run leaves follow the model
(5.2.1, 5.2.3), and every weed is cut by the tractor closest to it."""

from __future__ import annotations

import json
import math

from simbags import manifest, messages, record, seconds, tags

from robotale.sim.faults import parse_fault
from robotale.sim.plans import adjust


def test_a_short_agri_run_cuts_every_weed_and_its_tags_follow_the_model(short_agri, tmp_path):
    bag = record(short_agri, tmp_path / "runs")
    run = manifest(bag)
    assert run["outcome"] == {"status": "ended", "reason": ""}
    assert run["robots"] == {"drone": "Drone", "tractor_1": "Tractor", "tractor_2": "Tractor"}
    assert run["weeds"] == {"total": 2, "found": 2, "cut": 2}
    everything = tags(bag)
    cuts = [t for t in everything if t.activity == "cut_grass" and t.lifecycle == "complete"]
    assert len(cuts) == 2

    # weed_position! precedes the matching weed_position? of both tractors
    sends = [t for t in everything if t.activity == "weed_position!" and t.lifecycle == "start"]
    assert sends
    for send in sends:
        receivers = {
            t.robot: t
            for t in everything
            if t.activity == "weed_position?" and t.msg_id == send.msg_id
        }
        assert set(receivers) == {"tractor_1", "tractor_2"}
        assert all(seconds(r) > seconds(send) for r in receivers.values())
        assert all(r.payload == send.payload for r in receivers.values())

    # only the closest tractor (by the positions the tractors reported) moves and cuts
    for weed_sent in sends:
        weed = json.loads(weed_sent.payload)
        replies = [
            t
            for t in everything
            if t.activity == "tractor_position?"
            and t.robot == "drone"
            and t.lifecycle == "start"
            and seconds(weed_sent) < seconds(t) < seconds(weed_sent) + 10.5
        ]
        distance = {}
        for reply in replies:
            data = json.loads(reply.payload)
            where = data["vector"]
            distance[data["header"]["frame_id"]] = math.hypot(
                where["x"] - weed["x"], where["y"] - weed["y"]
            )
        closest = min(distance, key=distance.get)
        chosen = next(
            t
            for t in everything
            if t.activity == "closest_tractor!" and seconds(t) > seconds(weed_sent)
        )
        assert json.loads(chosen.payload) == {"data": closest}
    movers = sorted(t.robot for t in everything if t.activity == "move" and t.lifecycle == "start")
    cutters = sorted(t.robot for t in cuts)
    assert movers == cutters
    done_by = sorted(o["done_by"] for o in run["objects"])
    assert cutters == done_by

    # the drone takes off first and lands last
    drone = [t for t in everything if t.robot == "drone"]
    assert (drone[0].activity, drone[0].lifecycle) == ("take_off", "start")
    assert (drone[-1].activity, drone[-1].lifecycle) == ("land", "complete")
    order = [t.activity for t in drone if t.lifecycle == "start"]
    assert order.index("field_cleaned!") < order.index("return_to_base") < order.index("land")

    # the drone explores anew after each weed it handed to a tractor (figure 7.4's
    # closest_tractor! -> explore), and its last Explore, finding nothing more, ends the field
    handed = [t for t in drone if t.activity == "closest_tractor!" and t.lifecycle == "start"]
    explores = [t for t in drone if t.activity == "explore" and t.lifecycle == "start"]
    assert len(explores) == len(handed) + 1 == 3
    for chosen, again in zip(handed, explores[1:], strict=True):
        assert 0 <= seconds(again) - seconds(chosen) < 1.0
    found = [t for t in drone if t.activity == "weed_found!" and t.lifecycle == "start"]
    assert len(found) == 2  # each weed reported once, though the next Explore still sees it
    last = [t.activity for t in drone if t.lifecycle == "start"][-4:]
    assert last == ["explore", "field_cleaned!", "return_to_base", "land"]


def test_a_tractor_running_low_goes_home_charges_until_full_and_leaves_its_weed(
    short_agri, tmp_path
):
    one = adjust(short_agri, counts={"tractor": 1}, weeds=(1, 1))
    healthy = record(one, tmp_path / "healthy")
    move = next(t for t in tags(healthy) if t.activity == "move")
    begin = tags(healthy)[0].stamp.sec
    when = round(seconds(move) - begin + 1.0, 1)
    # runs are deterministic, so the faulty run has the healthy run's charge until the fault
    level = next(
        m.percentage
        for _, stamp, m in messages(healthy, {"/tractor_1/battery"})
        if stamp / 1e9 - begin >= when
    )
    rate = round((level - 0.1) / 5.0, 4)  # five seconds that leave it at about 10 %
    fault = parse_fault(f"battery:tractor_1@{when},rate={rate},for=5", ["drone", "tractor_1"])
    bag = record(one, tmp_path / "faulty", faults=(fault,))
    run = manifest(bag)
    assert run["outcome"]["status"] == "ended"
    assert run["weeds"] == {"total": 1, "found": 1, "cut": 0}
    tractor = [t for t in tags(bag) if t.robot == "tractor_1"]
    started = [t.activity for t in tractor if t.lifecycle == "start"]
    # the error is caught, then the handler it starts runs
    handler = started.index("low_battery")
    assert "move" in started[:handler] and "cut_grass" not in started
    after = [t for t in started[handler:] if not t.startswith("field_cleaned")]
    assert after[:4] == ["low_battery", "low_battery_handler", "return_to_base", "battery_full"]
    assert [t.lifecycle for t in tractor if t.activity == "move"] == [
        "start",
        "ate_abort",
    ]  # interrupted
    full = next(t for t in tractor if t.activity == "battery_full")
    levels = [
        m.percentage
        for _, stamp, m in messages(bag, {"/tractor_1/battery"})
        if stamp <= seconds(full) * 1e9
    ]
    assert min(levels) < 0.2 and levels[-1] >= 0.99 - 1e-6  # drained, then charged at home
