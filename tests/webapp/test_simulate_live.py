"""``robotale simulate --live``: a real agri run in pybullet watched by the monitor on the
simulation's bus, its tags stored as a live run (and its event knowledge graph) the dashboard
serves while it goes on. Set against the run's own recording: the live run's events are, row
by row, those ``prepare`` makes of the bag, and the battery alerts are the bag's battery
samples crossing the threshold, read back with rosbags; a plain cyclonedds reader on the DDS
domain gets the same alerts."""

from __future__ import annotations

import uuid

import pytest
from live_logs import assert_prepared

from robotale.cli import main
from robotale.thresholds import LOW_BATTERY_PERCENT


def battery_crossings(bag, robots) -> list[tuple[str, float, float]]:
    """(robot, stamp, percent) of each battery sample in the bag below the threshold whose
    robot's sample before was not (or which is its first), read with rosbags."""
    from rosbags.highlevel import AnyReader

    from robotale.sim.messages import typestore

    low: dict[str, bool] = {}
    crossings = []
    with AnyReader([bag], default_typestore=typestore()) as reader:
        topics = {f"/{r}/battery" for r in robots}
        wanted = [c for c in reader.connections if c.topic in topics]
        for connection, stamp, raw in reader.messages(connections=wanted):
            robot = connection.topic.split("/")[1]
            percent = 100.0 * reader.deserialize(raw, connection.msgtype).percentage
            below = percent < LOW_BATTERY_PERCENT
            if below and not low.get(robot, False):
                crossings.append((robot, stamp / 1e9, percent))
            low[robot] = below
    return crossings


def test_simulate_live_stores_the_run_as_recorded_and_prints_the_battery_alert(
    tmp_path, tmp_path_factory, monkeypatch, capsys, neo4j_driver, dashboard
):
    import json

    cyclonedds = pytest.importorskip("cyclonedds.domain")
    from cyclonedds.core import Policy, Qos
    from cyclonedds.sub import DataReader
    from cyclonedds.topic import Topic
    from dds_domain import loopback

    from robotale.ekg.live import delete_live, live_alerts, live_tags
    from robotale.ekg.logs import delete_log, log_info, stored_events
    from robotale.eventlog.preparing import prepare_recordings
    from robotale.results.live import live_events

    name = f"test_simlive_{uuid.uuid4().hex[:8]}"
    out = tmp_path / "runs"
    # tractor_1's battery drained 6 % a second for 14 s from 20 s: below 20 % on the way
    args = ["simulate", "agri", "--runs", "1", "--out", str(out), "--live", "--log", name]
    args += ["--pace", "1000", "--silence", "600", "--dashboard", dashboard.url]
    args += ["--fault", "battery:tractor_1@20,rate=0.06,for=14"]
    # a plain cyclonedds reader of the alerts the run publishes on the DDS domain too
    from robotale.fame_runtime.dds import leave
    from robotale.fame_runtime.rostypes import idl_type

    participant = cyclonedds.DomainParticipant(loopback(tmp_path_factory, monkeypatch))
    kept = Qos(
        Policy.Reliability.Reliable(10**9), Policy.Durability.TransientLocal, Policy.History.KeepAll
    )
    topic = Topic(participant, "rt/robotale/alerts", idl_type("std_msgs/msg/String"))
    reader = DataReader(participant, topic, qos=kept)
    try:
        assert main(args) == 0
        said = capsys.readouterr()
        published = [json.loads(s.data) for s in reader.take(N=100) if s.sample_info.valid_data]
        events = live_events(neo4j_driver, name)
        tags = live_tags(neo4j_driver, name)
        stored = live_alerts(neo4j_driver, name)
        graphed, status = stored_events(neo4j_driver, name), log_info(neo4j_driver, name)["status"]
    finally:
        leave(participant)
        delete_live(neo4j_driver, name)
        delete_log(neo4j_driver, name)  # the live run's event knowledge graph
    bag = out / "run_0001"
    prepared = prepare_recordings(bag)
    assert_prepared(events, prepared)
    # its event knowledge graph grew with it and holds every event, complete once it ended
    assert (graphed, status) == (len(prepared), "complete")

    # the dashboard answered on the live run once its first tag was stored
    page = f"{dashboard.url}/mission?log={name}&case={name}"
    assert f"# Mission page: {page}" in said.err
    assert f"# {name}: {len(tags)} tags stored" in said.err

    # the battery alerts: one per crossing of the threshold in the bag, at its stamp
    crossings = battery_crossings(bag, ["drone", "tractor_1", "tractor_2"])
    assert "tractor_1" in {robot for robot, _, _ in crossings}, crossings
    battery = sorted((a.robot, a.stamp, a.text) for a in stored if a.kind == "battery")
    assert [(r, s) for r, s, _ in battery] == [
        (r, pytest.approx(s, abs=1e-6)) for r, s, _ in sorted(crossings)
    ]
    for (_, _, text), (robot, _, percent) in zip(battery, sorted(crossings), strict=True):
        assert f"{robot}'s battery at {percent:.1f} %" in text
        assert f"# alert battery {robot}: {text}" in said.out
    assert {a.kind for a in stored} == {"battery"}, stored
    # and published on the DDS domain as stored
    assert sorted((a["stamp"], a["kind"], a["robot"], a["text"]) for a in published) == sorted(
        (a.stamp, a.kind, a.robot, a.text) for a in stored
    )
