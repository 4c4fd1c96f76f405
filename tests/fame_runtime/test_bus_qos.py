"""The in-process bus keeps DDS semantics: incompatible pairs never talk, transient-local
publishers serve late subscribers, only best-effort deliveries are lost at random."""

from dataclasses import replace

import pytest
from fame_suite import MODELS, build

from robotale.fame_runtime.bus import InProcessBus
from robotale.fame_runtime.check import check
from robotale.fame_runtime.clock import SimClock
from robotale.fame_runtime.parser import parse
from robotale.fame_runtime.qos import DEFAULT_QOS

POINT = "geometry_msgs/msg/Point"
RELIABLE = DEFAULT_QOS
BEST_EFFORT = replace(DEFAULT_QOS, reliability="best_effort")
LATCHED = replace(DEFAULT_QOS, durability="transient_local", depth=2)


def test_the_mission_delivers_exactly_the_pairs_fame_check_calls_compatible():
    warnings: list[str] = []
    mission, tags = build("qos.bpmn", robots=["drone", "tractor_1"])
    mission.bus.on_warning = warnings.append
    mission.run(until=60)
    report = check(parse(MODELS / "qos.bpmn"))
    blocked = {p.publisher.topic for p in report.pairs if not p.compatible}
    assert blocked == {"/weed_position", "/tractor_position"}  # figure 5.14 of the thesis
    caught = {t.activity for t in tags if t.msg_role == "receive"}
    # nothing crosses a pair fame check refuses: the drone throws weed_position best effort,
    # the tractor's start event asks for reliable, so the tractor never starts
    assert not caught
    assert not [t for t in tags if t.robot == "tractor_1"]
    assert len(warnings) == 1 and warnings[0].startswith("/weed_position: drone and tractor_1")
    assert "reliability: the publisher offers best_effort" in warnings[0]


def test_each_pair_warns_once_however_often_it_publishes():
    clock = SimClock()
    warnings: list[str] = []
    bus = InProcessBus(clock, on_warning=warnings.append)
    got: list = []
    bus.subscribe("/p", got.append, msgtype=POINT, qos=RELIABLE, owner="b")
    for _ in range(3):
        bus.publish("/p", {}, msgtype=POINT, sender="a", qos=BEST_EFFORT)
    bus.publish("/p", {}, msgtype="std_msgs/msg/String", sender="a", qos=RELIABLE)
    bus.publish("/p", {"x": 1.0}, msgtype=POINT, sender="a", qos=RELIABLE)
    clock.run()
    assert [e.data for e in got] == [{"x": 1.0}]
    assert len(warnings) == 2 and bus.warnings == warnings
    assert "type: the publisher sends std_msgs/msg/String" in warnings[1]


def test_transient_local_publishers_serve_late_subscribers_their_last_depth():
    clock = SimClock()
    bus = InProcessBus(clock)
    for x in (1.0, 2.0, 3.0):
        bus.publish("/p", {"x": x}, msgtype=POINT, sender="a", qos=LATCHED)
    late, volatile, shallow = [], [], []
    bus.subscribe("/p", late.append, msgtype=POINT, qos=LATCHED)
    bus.subscribe("/p", volatile.append, msgtype=POINT)
    bus.subscribe("/p", shallow.append, qos=replace(LATCHED, depth=1))
    clock.run()
    assert [e.data["x"] for e in late] == [2.0, 3.0]  # the writer keeps depth 2
    assert volatile == []  # a volatile reader asks for no history
    assert [e.data["x"] for e in shallow] == [3.0]  # the reader keeps depth 1


def test_a_volatile_publisher_keeps_nothing_for_late_subscribers():
    clock = SimClock()
    bus = InProcessBus(clock)
    bus.publish("/p", {"x": 1.0}, msgtype=POINT, qos=RELIABLE)
    late: list = []
    bus.subscribe("/p", late.append, qos=replace(DEFAULT_QOS, durability="transient_local"))
    clock.run()
    assert late == [] and bus.warnings == []
    bus.publish("/p", {"x": 2.0}, msgtype=POINT, qos=RELIABLE)
    clock.run()
    assert late == []  # volatile offered, transient-local requested: they never talk
    assert len(bus.warnings) == 1 and "durability" in bus.warnings[0]


@pytest.mark.parametrize("seed", [1, 2])
def test_only_best_effort_deliveries_are_lost(seed):
    clock = SimClock()
    bus = InProcessBus(clock, loss=0.5, seed=seed)
    reliable, lossy = [], []
    bus.subscribe("/r", reliable.append)
    bus.subscribe("/b", lossy.append, qos=BEST_EFFORT)
    for _ in range(400):
        bus.publish("/r", {}, msgtype=POINT)
        bus.publish("/b", {}, msgtype=POINT, qos=BEST_EFFORT)
    clock.run()
    assert len(reliable) == 400
    assert 120 < len(lossy) < 280  # about half of 400 (binomial, 7 standard deviations)


def test_fame_run_delivers_nothing_across_a_pair_fame_check_refuses(capsys):
    from robotale.cli import main

    model = str(MODELS / "qos.bpmn")
    assert main(["fame", "check", model]) == 1
    refused = [line for line in capsys.readouterr().out.splitlines() if "INCOMPATIBLE" in line]
    code = main(["fame", "run", model, "--robots", "drone,tractor_1", "--until", "60"])
    captured = capsys.readouterr()
    rows = [line.split("\t") for line in captured.out.splitlines()]
    warnings = [line for line in captured.err.splitlines() if line.startswith("# warning:")]
    # the drone's best-effort weed_position is one of the pairs fame check refuses
    assert any(line.lstrip().startswith("/weed_position: Drone d_weed") for line in refused)
    assert [r[2:4] for r in rows if r[1] == "drone"] == [
        ["weed_position!", "start"],
        ["weed_position!", "complete"],
    ]
    assert not [r for r in rows if r[1] == "tractor_1"]  # never received, never started
    assert len(warnings) == 1 and warnings[0].startswith("# warning: /weed_position: drone")
    # as ROS 2 would: the drone waits for an answer that never comes, and the run says so
    assert code == 1
    assert "# drone is at intermediateCatchEvent d_position (tractor_position)" in captured.err
