"""Recordings: rosbag2 directories that read back with rosbags alone, the same for the same
seed, different for another."""

from __future__ import annotations

import itertools
import json

import pytest
from rosbags.rosbag2 import Reader
from simbags import manifest, messages, record, typestore

from robotale.fame_runtime.tags import TAG_TYPE


def raw_messages(bag):
    with Reader(bag) as reader:
        return [(c.topic, c.msgtype, t, bytes(raw)) for c, t, raw in reader.messages()]


def test_the_same_seed_gives_the_same_bag_and_another_seed_other_weeds(short_agri, tmp_path):
    first = record(short_agri, tmp_path / "a", seed=7)
    again = record(short_agri, tmp_path / "b", seed=7)
    other = record(short_agri, tmp_path / "c", seed=8)
    recorded = raw_messages(first)
    assert len(recorded) > 500
    assert recorded == raw_messages(again)
    weeds = [(o["x"], o["y"]) for o in manifest(first)["setup"]["objects"]]
    assert weeds != [(o["x"], o["y"]) for o in manifest(other)["setup"]["objects"]]
    found = {m.x for _, _, m in messages(first, {"/weed_found"})}
    assert found == {x for x, _ in weeds}
    assert found != {m.x for _, _, m in messages(other, {"/weed_found"})}


@pytest.mark.parametrize("storage", ["sqlite3", "mcap"])
def test_a_bag_reads_back_with_the_topics_and_types_it_announces(short_agri, tmp_path, storage):
    bag = record(short_agri, tmp_path / "runs", storage=storage)
    announced = manifest(bag)["topics"]
    store = typestore()
    with Reader(bag) as reader:
        assert {c.topic: c.msgtype for c in reader.connections} == {
            topic: entry["type"] for topic, entry in announced.items()
        }
        counts = dict.fromkeys(announced, 0)
        for connection, _, raw in reader.messages():
            store.deserialize_cdr(raw, connection.msgtype)
            counts[connection.topic] += 1
    suffix = ".mcap" if storage == "mcap" else ".db3"
    assert [p.suffix for p in bag.iterdir() if p.suffix in (".mcap", ".db3")] == [suffix]
    assert counts == {topic: entry["count"] for topic, entry in announced.items()}
    robots = ("drone", "tractor_1", "tractor_2")
    for robot in robots:
        assert announced[f"/{robot}/tag"]["type"] == TAG_TYPE
        assert announced[f"/{robot}/odom"]["type"] == "nav_msgs/msg/Odometry"
        assert announced[f"/{robot}/battery"]["type"] == "sensor_msgs/msg/BatteryState"
    signals = {
        "/weed_found": "geometry_msgs/msg/Vector3",
        "/weed_position": "geometry_msgs/msg/Vector3",
        "/tractor_position": "geometry_msgs/msg/Vector3Stamped",
        "/closest_tractor": "std_msgs/msg/String",
        "/field_cleaned": "std_msgs/msg/Empty",
    }
    assert {t: announced[t]["type"] for t in signals} == signals
    assert all(announced[t]["count"] > 0 for t in signals)


def test_odometry_and_battery_are_recorded_at_the_chosen_rate_in_simulated_time(
    short_agri, tmp_path
):
    bag = record(short_agri, tmp_path / "runs")
    run = manifest(bag)
    odom = messages(bag, {"/drone/odom"})
    stamps = [t / 1e9 for _, t, _ in odom]
    gaps = [b - a for a, b in itertools.pairwise(stamps)]
    assert min(gaps) >= 0.5 - 1e-6  # 2 Hz by default
    assert max(gaps) <= 0.5 + 0.1 + 1e-6  # the next control step after each half second
    header = odom[0][2].header
    assert header.stamp.sec + header.stamp.nanosec / 1e9 == pytest.approx(stamps[0], abs=1e-6)
    assert stamps[-1] - stamps[0] == pytest.approx(run["duration"], abs=0.6)
    battery = [m.percentage for _, _, m in messages(bag, {"/drone/battery"})]
    assert all(0 <= p <= 1 for p in battery)
    assert min(battery) < battery[0]  # flying drains it (landed on its base, it charges again)
    tags = [m for _, _, m in messages(bag, {"/drone/tag"})]
    assert json.loads(next(t for t in tags if t.activity == "weed_found!").payload).keys() == {
        "x",
        "y",
        "z",
    }


def test_more_robot_topics_are_recorded_when_asked_and_sensors_read_the_world(short_agri, tmp_path):
    bag = record(short_agri, tmp_path / "runs", extra_topics=("range", "cmd_vel"))
    announced = manifest(bag)["topics"]
    assert announced["/drone/range"]["type"] == "sensor_msgs/msg/Range"
    assert announced["/tractor_1/cmd_vel"]["type"] == "geometry_msgs/msg/Twist"
    assert "/drone/cmd_vel" in announced and "/tractor_2/range" in announced
    heights = [m.range for _, _, m in messages(bag, {"/drone/range"})]
    assert max(heights) == pytest.approx(1.5, abs=1e-3)  # the ground, seen from its altitude
    assert min(heights) == pytest.approx(0.0, abs=1e-3)  # landed
    tractor = [m.range for _, _, m in messages(bag, {"/tractor_1/range"})]
    assert all(0 < r <= 2.0 for r in tractor)
    forward = [m.linear.x for _, _, m in messages(bag, {"/tractor_1/cmd_vel"})]
    assert max(forward) > 0 and forward[-1] == 0.0  # it drove, and stopped


def test_a_runs_storage_file_carries_the_runs_name(short_agri, tmp_path):
    bag = record(short_agri, tmp_path / "runs")
    assert sorted(p.name for p in bag.iterdir()) == [
        "metadata.yaml",
        "robotale-run.json",
        "robotale-truth.jsonl",
        "run_0001.db3",
    ]
    assert not list((tmp_path / "runs").glob(".*")), "no hidden partial folder is left behind"
