"""``robotale annotate``: the recording copied as MCAP with activities, messages and findings.

The copy is read back with the ``mcap`` package's reader and with rosbags (never robotale's
reader): every original message must be there byte for byte, and the added topics must say
what the hand count of the recording says.
"""

from __future__ import annotations

from collections import defaultdict
from pathlib import Path

import pytest
from bagbuilder import agri_like, nanos
from mcap.reader import make_reader
from rosbags.rosbag2 import Reader
from rosbags.typesys import Stores, get_typestore

from robotale.cli import main

pytestmark = pytest.mark.filterwarnings("ignore::UserWarning")


def recording(bag_builder, path, storage):
    """The agri-like run, with a message m2 the drone sends and nobody receives."""
    b = agri_like(bag_builder)
    b.tag(8.0, "drone", "weed_position!", "start", "m2", "send", '{"x": 9}')
    b.tag(8.0, "drone", "weed_position!", "complete", "m2", "send", '{"x": 9}')
    return b.write(path, storage=storage)


def messages_by_rosbags(bag) -> dict[str, list[tuple[int, bytes]]]:
    found = defaultdict(list)
    with Reader(bag) as reader:
        for connection, time, raw in reader.messages():
            found[connection.topic].append((time, bytes(raw)))
    return dict(found)


def messages_by_mcap(bag) -> dict[str, list[tuple[int, bytes]]]:
    found = defaultdict(list)
    (file,) = bag.glob("*.mcap")
    with file.open("rb") as stream:
        for _, channel, message in make_reader(stream).iter_messages(log_time_order=True):
            found[channel.topic].append((message.log_time, bytes(message.data)))
    return dict(found)


#: the drone's current activity after each of its tag events, counted by hand (agri_like)
DRONE = [
    (0.5, "take_off"),
    (2.5, "idle"),
    (2.5, "explore"),
    (5.2, "idle"),
    (5.2, "weed_position!"),
    (5.2, "idle"),
    (8.0, "weed_position!"),
    (8.0, "idle"),
    (9.5, "land"),
    (10.5, "idle"),
]


@pytest.mark.parametrize("storage", ["sqlite3", "mcap"])
def test_the_copy_keeps_every_message_and_adds_the_mined_mission(
    tmp_path, bag_builder, capsys, storage
):
    bag = recording(bag_builder, tmp_path / "runs" / "run_1", storage)
    out = tmp_path / "annotated"
    assert main(["annotate", str(tmp_path / "runs"), "--out", str(out)]) == 0
    assert "run_1 copied with" in capsys.readouterr().out
    copy = out / "run_1"
    original = messages_by_rosbags(bag)
    by_mcap, by_rosbags = messages_by_mcap(copy), messages_by_rosbags(copy)
    for topic, messages in original.items():
        assert by_mcap[topic] == messages, topic
        assert by_rosbags[topic] == messages, topic
    added = sorted(set(by_mcap) - set(original))
    assert added == [
        "/robotale/drone/activity",
        "/robotale/drone/activity_index",
        "/robotale/log",
        "/robotale/tractor_1/activity",
        "/robotale/tractor_1/activity_index",
    ]
    store = get_typestore(Stores.ROS2_HUMBLE)
    states = [
        (time, store.deserialize_cdr(raw, "std_msgs/msg/String").data)
        for time, raw in by_rosbags["/robotale/drone/activity"]
    ]
    assert states == [(nanos(t), activity) for t, activity in DRONE]
    names = sorted({"take_off", "explore", "weed_position!", "land", "weed_position?", "move"})
    numbers = [
        store.deserialize_cdr(raw, "std_msgs/msg/Int32").data
        for _, raw in by_rosbags["/robotale/drone/activity_index"]
    ]
    assert numbers == [0 if a == "idle" else names.index(a) + 1 for _, a in DRONE]
    entries = [
        (time, store.deserialize_cdr(raw, "rcl_interfaces/msg/Log"))
        for time, raw in by_rosbags["/robotale/log"]
    ]
    texts = [(time, log.level, log.msg) for time, log in entries]
    assert (nanos(5.2), 20, "drone sent message m1 (weed_position!)") in texts
    assert (nanos(5.3), 20, "tractor_1 received message m1 (weed_position!)") in texts
    lost = [t for t in texts if t[2].startswith("lost message")]
    assert lost == [
        (nanos(8.0), 30, "lost message: m2 (weed_position!) sent by drone was never received")
    ]
    # each entry's stamp is its time in the bag
    assert all(log.stamp.sec * 10**9 + log.stamp.nanosec == time for time, log in entries)


def test_an_existing_copy_is_not_overwritten(tmp_path, bag_builder, capsys):
    recording(bag_builder, tmp_path / "runs" / "run_1", "sqlite3")
    (tmp_path / "out" / "run_1").mkdir(parents=True)
    assert main(["annotate", str(tmp_path / "runs"), "--out", str(tmp_path / "out")]) == 1
    assert "run_1 exists already" in capsys.readouterr().err


def test_the_slow_instance_of_a_bottleneck_is_a_finding_of_its_run(tmp_path, bag_builder):
    """tractor_1's move takes 2, 2.2 and 8 s in three runs: only the third is slower than
    its median, and only that run's copy says so, when it ends."""
    for k, move in enumerate((2, 2.2, 8)):
        b = bag_builder()
        b.tag(0.5, "drone", "scan", "start").tag(2.5, "drone", "scan", "complete")
        b.tag(3, "tractor_1", "move", "start").tag(3 + move, "tractor_1", "move", "complete")
        b.tag(12, "tractor_1", "spray", "start").tag(13, "tractor_1", "spray", "complete")
        b.write(tmp_path / "runs" / f"run_{k}")
    assert main(["annotate", str(tmp_path / "runs"), "--out", str(tmp_path / "out")]) == 0
    store = get_typestore(Stores.ROS2_HUMBLE)
    found = {}
    for k in range(3):
        logged = messages_by_rosbags(tmp_path / "out" / f"run_{k}").get("/robotale/log", [])
        found[k] = [
            (time, store.deserialize_cdr(raw, "rcl_interfaces/msg/Log").msg) for time, raw in logged
        ]
    assert found[0] == found[1] == []
    assert len(found[2]) == 1
    time, text = found[2][0]
    assert time == nanos(11)
    assert text.startswith("bottleneck instance: move of tractor_1 took 8.000 s (median 2.200 s)")


def test_with_a_model_a_deviation_is_a_finding_at_its_start(tmp_path, bag_builder):
    """The rover's sequence model has no dance between prepare and measure."""
    model = Path(__file__).resolve().parents[1] / "fame_runtime" / "models" / "sequence.bpmn"
    b = bag_builder()
    for k, activity in enumerate(["prepare", "dance", "measure", "carry_on"]):
        b.tag(k + 1, "rover", activity, "start").tag(k + 1.5, "rover", activity, "complete")
    b.write(tmp_path / "run")
    out = tmp_path / "out"
    assert main(["annotate", str(tmp_path / "run"), "--out", str(out), "--model", str(model)]) == 0
    store = get_typestore(Stores.ROS2_HUMBLE)
    logged = messages_by_rosbags(out / "run")["/robotale/log"]
    texts = [
        (time, store.deserialize_cdr(raw, "rcl_interfaces/msg/Log").msg) for time, raw in logged
    ]
    assert texts == [(nanos(2), "deviation: dance of rover is not where the model allows it")]
