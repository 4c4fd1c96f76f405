"""Messages read in batches from MCAP chunk indexes equal what other readers read one by one."""

from __future__ import annotations

import struct

import numpy as np
import pytest
from mcap.reader import make_reader
from rosbags.rosbag2 import CompressionFormat, CompressionMode, Reader, StoragePlugin, Writer
from rosbags.typesys import Stores, get_typestore

from robotale.errors import InputError
from robotale.eventlog.messages import Batch, mcap_batches
from robotale.eventlog.rosbag import Bag

BIG = 300_000  # bytes of a "camera" message: a few to a 1 MB chunk, as with real images


def write_bag(path, compression=None) -> None:
    """Three topics: small numbered messages, rare big ones, and some with equal times."""
    store = get_typestore(Stores.ROS2_HUMBLE)
    rng = np.random.default_rng(7)
    writer = Writer(path, version=9, storage_plugin=StoragePlugin.MCAP)
    if compression is not None:
        writer.set_compression(compression, CompressionFormat.ZSTD)
    with writer:
        small = writer.add_connection("/a/small", "std_msgs/msg/String", typestore=store)
        big = writer.add_connection("/a/camera", "std_msgs/msg/String", typestore=store)
        tied = writer.add_connection("/b/tied", "std_msgs/msg/String", typestore=store)
        string = store.types["std_msgs/msg/String"]
        for k in range(400):
            text = "x" * int(rng.integers(0, 40)) + str(k)
            writer.write(
                small, 1_000 + 10 * k, store.serialize_cdr(string(data=text), small.msgtype)
            )
            if k % 20 == 0:
                image = string(data="i" * BIG)
                writer.write(big, 1_000 + 10 * k + 1, store.serialize_cdr(image, big.msgtype))
            if k % 7 == 0:  # equal times keep the order they were written in
                for n in range(3):
                    raw = store.serialize_cdr(string(data=f"{k}-{n}"), tied.msgtype)
                    writer.write(tied, 1_000 + 10 * k + 5, raw)


def batched(path, topics) -> dict[str, list[tuple[int, bytes]]]:
    """What :func:`mcap_batches` reads of ``topics``, as (time, bytes) per topic in order."""
    mcap = next(path.glob("*.mcap"))
    with Reader(path) as reader:
        ids = {c.id: c.topic for c in reader.connections if c.topic in topics}
    batches = mcap_batches(mcap, ids)
    assert batches is not None
    read: dict[str, list[tuple[int, bytes]]] = {topic: [] for topic in topics}
    for channel, batch in batches:
        read[ids[channel]].extend(
            (int(batch.recorded[k]), batch.message(k)) for k in range(len(batch))
        )
    return {topic: sorted(messages, key=lambda m: m[0]) for topic, messages in read.items()}


@pytest.mark.parametrize("compression", [None, "storage"])
def test_batches_hold_what_the_mcap_package_and_rosbags_read(tmp_path, compression):
    mode = CompressionMode.STORAGE if compression else None
    write_bag(tmp_path / "bag", mode)
    topics = ["/a/small", "/b/tied"]
    read = batched(tmp_path / "bag", topics)
    with open(next((tmp_path / "bag").glob("*.mcap")), "rb") as file:
        by_mcap = {topic: [] for topic in topics}
        for _, channel, message in make_reader(file).iter_messages(topics=topics):
            by_mcap[channel.topic].append((message.log_time, bytes(message.data)))
    with Reader(tmp_path / "bag") as reader:
        chosen = [c for c in reader.connections if c.topic in topics]
        by_rosbags = {topic: [] for topic in topics}
        for connection, recorded, raw in reader.messages(connections=chosen):
            by_rosbags[connection.topic].append((recorded, bytes(raw)))
    assert len(read["/a/small"]) == 400 and len(read["/b/tied"]) == 3 * 58
    assert read == by_mcap == by_rosbags


def test_a_batch_from_messages_read_one_by_one_keeps_them():
    raws = [b"", b"abc", b"\x00" * 7, b"z"]
    batch = Batch.of([4, 3, 2, 1], raws)
    assert [batch.message(k) for k in range(4)] == raws
    assert batch.recorded.tolist() == [4, 3, 2, 1]


def test_a_message_index_that_does_not_match_its_chunk_is_one_sentence(tmp_path):
    write_bag(tmp_path / "bag")
    mcap = next((tmp_path / "bag").glob("*.mcap"))
    with open(mcap, "rb") as file:
        summary = make_reader(file).get_summary()
    with Reader(tmp_path / "bag") as reader:
        small = next(c.id for c in reader.connections if c.topic == "/a/small")
    at = summary.chunk_indexes[0].message_index_offsets[small]
    data = bytearray(mcap.read_bytes())
    # the index's first entry: (log time, offset) after opcode, length, channel, array length
    struct.pack_into("<Q", data, at + 15 + 8, 3)  # a message that is not at offset 3
    mcap.write_bytes(bytes(data))
    with pytest.raises(InputError) as error, Bag(tmp_path / "bag") as bag:
        bag.tables({"/a/small": {"data": "data"}})
    assert str(error.value) == (
        f"{tmp_path / 'bag'} cannot be read: the message index of channel {small} does not "
        "match its chunk."
    )
