"""Numeric fields read in bulk from CDR bytes equal what rosbags decodes, message by message."""

from __future__ import annotations

from operator import attrgetter

import numpy as np
import pytest
from rosbags.typesys import Stores, get_types_from_msg, get_typestore

from robotale.eventlog.cdrlayout import Layout, columns
from robotale.eventlog.messages import Batch
from robotale.eventlog.rosbag import Bag

MIXED = "mixed_msgs/msg/Mixed"
MIXED_MSG = """\
string label
float32[] readings
std_msgs/Header[2] headers
uint8 flag
float64 value
int16 small
bool ok
float32 ratio
"""
WANTED = ["flag", "value", "small", "ok", "ratio"]


@pytest.fixture(scope="module")
def store():
    store = get_typestore(Stores.ROS2_HUMBLE)
    store.register(get_types_from_msg(MIXED_MSG, MIXED))
    return store


def mixed(store, rng, label_length: int, readings: int):
    header = store.types["std_msgs/msg/Header"]
    stamp = store.types["builtin_interfaces/msg/Time"]
    return store.types[MIXED](
        label="x" * label_length,
        readings=rng.normal(size=readings).astype(np.float32),
        headers=[header(stamp=stamp(sec=1, nanosec=2), frame_id="f" * label_length)] * 2,
        flag=int(rng.integers(0, 256)),
        value=float(rng.normal()),
        small=int(rng.integers(-30000, 30000)),
        ok=bool(rng.integers(0, 2)),
        ratio=float(np.float32(rng.uniform())),
    )


def test_bulk_values_equal_rosbags_decoding_for_messages_of_one_layout(store):
    rng = np.random.default_rng(3)
    raws = [bytes(store.serialize_cdr(mixed(store, rng, 5, 3), MIXED)) for _ in range(200)]
    layout = Layout.of(raws[0], MIXED, WANTED, store.fielddefs)
    assert layout is not None and all(layout.fits(raw) for raw in raws)
    bulk = columns(layout, b"".join(raw[: layout.end] for raw in raws))
    decoded = [attrgetter(*WANTED)(store.deserialize_cdr(raw, MIXED)) for raw in raws]
    for k in range(len(WANTED)):
        assert bulk[k].tolist() == [row[k] for row in decoded]


def test_a_message_whose_lengths_differ_does_not_fit(store):
    rng = np.random.default_rng(4)
    first = bytes(store.serialize_cdr(mixed(store, rng, 5, 3), MIXED))
    layout = Layout.of(first, MIXED, WANTED, store.fielddefs)
    for label, readings in ((6, 3), (5, 4), (1, 0)):
        other = bytes(store.serialize_cdr(mixed(store, rng, label, readings), MIXED))
        assert not layout.fits(other)
    assert Layout.of(b"\x00\x00" + first[2:], MIXED, WANTED, store.fielddefs) is None  # big-endian
    assert Layout.of(first, MIXED, ["label"], store.fielddefs) is None  # strings: one by one


def test_a_whole_batch_is_checked_as_each_message_would_be(store):
    rng = np.random.default_rng(5)
    shapes = [(5, 3), (5, 3), (6, 3), (5, 4), (5, 3), (1, 0), (5, 3)]
    raws = [bytes(store.serialize_cdr(mixed(store, rng, *s), MIXED)) for s in shapes]
    raws.append(raws[0][:-1][: Layout.of(raws[0], MIXED, WANTED, store.fielddefs).end - 1])
    raws.append(b"\x00\x00" + raws[1][2:])  # big-endian: another header
    layout = Layout.of(raws[0], MIXED, WANTED, store.fielddefs)
    rows, heads = layout.fitting(Batch.of(range(len(raws)), raws))
    assert rows.tolist() == [k for k, raw in enumerate(raws) if layout.fits(raw)] == [0, 1, 4, 6]
    assert heads.tobytes() == b"".join(raws[k][: layout.end] for k in rows)


def test_a_topic_mixing_layouts_reads_every_message_right(tmp_path, bag_builder):
    b = bag_builder()
    frames = ["odom", "odom", "map", "odom", "a_much_longer_frame", "odom"]
    for t, frame in enumerate(frames):
        b.odom(t, "drone", t + 0.5, -t, 2 * t, frame=frame)
    paths = {"x": "pose.pose.position.x", "z": "pose.pose.position.z"}
    with Bag(b.write(tmp_path / "bag")) as bag:
        rows = bag._rows("/drone/odom", paths)
        for _, batch in bag._batches(bag.reader.connections, None):
            rows.add(batch)
    assert rows.bulk_at == [0, 1, 3, 5] and rows.one_by_one_at == [2, 4]
    table = rows.table(list(paths), bag_time=False)
    assert table["x"].tolist() == [t + 0.5 for t in range(6)]
    assert table["z"].tolist() == [2.0 * t for t in range(6)]
    assert table["x"].dtype == np.float64
