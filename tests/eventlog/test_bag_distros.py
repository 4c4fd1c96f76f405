"""robotale's own bags, read back without robotale or rosbags, for each ROS 2 distribution.

What each distribution's reader requires of metadata.yaml is written here from rosbag2's
``rosbag2_storage`` YAML decoding (``metadata_io.cpp`` on the humble branch,
``include/rosbag2_storage/yaml.hpp`` on iron and jazzy; releases 0.15.12, 0.22.7 and 0.26.5, the
same as the branches of October 2024): the keys it reads for the version it finds, and the YAML
kind each must have.
"""

from __future__ import annotations

import sqlite3

import pytest
import yaml
from mcap.reader import make_reader

from robotale.fame_runtime.bus import Envelope
from robotale.fame_runtime.tags import TAG_TYPE, Tag
from robotale.sim.recorder import Recorder

#: distribution -> (metadata version its rosbag2 writes, newest version whose fields it decodes)
WRITES = {"humble": 5, "iron": 7, "jazzy": 9}
#: keys every reader decodes (version >= 5), and the YAML kind of each
BAG_KEYS = {
    "version": int,
    "storage_identifier": str,
    "duration": dict,
    "starting_time": dict,
    "message_count": int,
    "topics_with_message_count": list,
    "relative_file_paths": list,
    "compression_format": str,
    "compression_mode": str,
    "files": list,
}
FILE_KEYS = {"path": str, "starting_time": dict, "duration": dict, "message_count": int}


def required(distro: str, version: int) -> tuple[dict, dict]:
    """(bag keys, topic_metadata keys) ``distro``'s reader decodes from a file of ``version``."""
    bag = dict(BAG_KEYS)
    topic = {"name": str, "type": str, "serialization_format": str}
    # all three read offered_qos_profiles as a string up to version 8; only Jazzy knows 9's list
    topic["offered_qos_profiles"] = list if version >= 9 else str
    if distro != "humble":
        if version >= 6:
            bag["custom_data"] = (dict, type(None))  # an empty map is written as null
        if version >= 7:
            topic["type_description_hash"] = str
    if distro == "jazzy" and version >= 8:
        bag["ros_distro"] = str
    return bag, topic


def assert_kinds(mapping: dict, kinds: dict, where: str) -> None:
    for key, kind in kinds.items():
        assert key in mapping, f"{where} lacks {key}"
        assert isinstance(mapping[key], kind), f"{where}: {key} is {mapping[key]!r}"


def record(path, storage: str, distro: str) -> dict[str, int]:
    """A short recording of two tags; how many messages each topic got."""
    recorder = Recorder(path, robots=["drone"], announced={}, storage=storage, distro=distro)
    for stamp, lifecycle in ((1.0, "start"), (2.5, "complete")):
        tag = Tag(stamp, "drone", "take_off", lifecycle)
        recorder.tap(Envelope("/drone/tag", tag, TAG_TYPE, stamp))
    recorder.close()
    return {"/drone/tag": 2}


@pytest.mark.parametrize("storage", ["sqlite3", "mcap"])
@pytest.mark.parametrize("distro", ["humble", "iron", "jazzy"])
def test_the_written_metadata_is_what_each_distribution_reads(tmp_path, storage, distro):
    bag = tmp_path / "run"
    record(bag, storage, distro)
    info = yaml.safe_load((bag / "metadata.yaml").read_text())["rosbag2_bagfile_information"]
    assert info["version"] == WRITES[distro]
    # every distribution at least as new as the one chosen reads it
    for reader in [d for d in WRITES if WRITES[d] >= WRITES[distro]]:
        bag_keys, topic_keys = required(reader, info["version"])
        assert_kinds(info, bag_keys, f"{reader}: metadata")
        for entry in info["topics_with_message_count"]:
            assert_kinds(entry["topic_metadata"], topic_keys, f"{reader}: {entry}")
        for file in info["files"]:
            assert_kinds(file, FILE_KEYS, f"{reader}: files")
    qos = info["topics_with_message_count"][0]["topic_metadata"]["offered_qos_profiles"]
    profiles = yaml.safe_load(qos) if isinstance(qos, str) else qos
    assert profiles and profiles[0]["depth"] == 10  # a real profile, not an empty list


def test_older_distributions_cannot_read_what_jazzy_writes(tmp_path):
    """The check above can fail: Jazzy's QoS list is not the string Humble and Iron read."""
    record(tmp_path / "run", "sqlite3", "jazzy")
    info = yaml.safe_load((tmp_path / "run" / "metadata.yaml").read_text())
    info = info["rosbag2_bagfile_information"]
    for reader in ("humble", "iron"):
        _, topic_keys = required(reader, 8)  # what they expect below their own version
        with pytest.raises(AssertionError):
            assert_kinds(info["topics_with_message_count"][0]["topic_metadata"], topic_keys, "")


@pytest.mark.parametrize("distro", ["humble", "iron", "jazzy"])
def test_sqlite3_bags_read_back_with_sqlite(tmp_path, distro):
    counts = record(tmp_path / "run", "sqlite3", distro)
    info = yaml.safe_load((tmp_path / "run" / "metadata.yaml").read_text())
    info = info["rosbag2_bagfile_information"]
    database = tmp_path / "run" / info["relative_file_paths"][0]
    with sqlite3.connect(database) as connection:
        rows = connection.execute(
            "SELECT topics.name, topics.type, COUNT(*) FROM messages "
            "JOIN topics ON topics.id = messages.topic_id GROUP BY topics.name"
        ).fetchall()
        stored = connection.execute("SELECT metadata_version FROM metadata").fetchone()[0]
    connection.close()
    assert {name: n for name, _, n in rows} == counts
    assert {kind for _, kind, _ in rows} == {TAG_TYPE}
    assert stored == WRITES[distro]
    listed = {
        e["topic_metadata"]["name"]: e["message_count"] for e in info["topics_with_message_count"]
    }
    assert {t: n for t, n in listed.items() if n} == counts


@pytest.mark.parametrize("distro", ["humble", "iron", "jazzy"])
def test_mcap_bags_read_back_with_the_mcap_reader(tmp_path, distro):
    counts = record(tmp_path / "run", "mcap", distro)
    info = yaml.safe_load((tmp_path / "run" / "metadata.yaml").read_text())
    info = info["rosbag2_bagfile_information"]
    with open(tmp_path / "run" / info["relative_file_paths"][0], "rb") as stream:
        messages = list(make_reader(stream).iter_messages())
    seen: dict[str, int] = {}
    for schema, channel, _ in messages:
        assert (schema.name, schema.encoding, channel.message_encoding) == (
            TAG_TYPE,
            "ros2msg",
            "cdr",
        )
        seen[channel.topic] = seen.get(channel.topic, 0) + 1
    assert seen == counts
    assert info["message_count"] == sum(counts.values())


@pytest.mark.parametrize("distro", ["humble", "iron", "jazzy"])
def test_the_metadata_inside_an_mcap_file_is_the_distributions(tmp_path, distro):
    """What rosbag2_storage_mcap writes (mcap_storage.cpp on each branch): Humble and Iron a
    record {ROS_DISTRO}; Jazzy {serialized_metadata}, which its read_metadata decodes as
    yaml.hpp's BagMetadata of the version it states."""
    counts = record(tmp_path / "run", "mcap", distro)
    info = yaml.safe_load((tmp_path / "run" / "metadata.yaml").read_text())
    info = info["rosbag2_bagfile_information"]
    with open(tmp_path / "run" / info["relative_file_paths"][0], "rb") as stream:
        reader = make_reader(stream)
        records = [(m.name, m.metadata) for m in reader.iter_metadata()]
        seen = sum(1 for _ in reader.iter_messages())
        indexed = reader.get_summary().chunk_indexes
    assert seen == sum(counts.values()) and all(c.message_index_offsets for c in indexed)
    if distro != "jazzy":
        assert records == [("rosbag2", {"ROS_DISTRO": distro})]
        return
    [(name, data)] = records
    assert name == "rosbag2" and list(data) == ["serialized_metadata"]
    inside = yaml.safe_load(data["serialized_metadata"])
    assert inside == info and inside["version"] == 9 and inside["ros_distro"] == "jazzy"
    bag_keys, topic_keys = required("jazzy", inside["version"])
    assert_kinds(inside, bag_keys, "serialized_metadata")
    for entry in inside["topics_with_message_count"]:
        assert_kinds(entry["topic_metadata"], topic_keys, entry["topic_metadata"]["name"])


def read_back(bag) -> dict[str, int]:
    """Messages per topic of a bag's storage files, read without robotale or rosbags."""
    seen: dict[str, int] = {}
    for database in bag.glob("*.db3"):
        with sqlite3.connect(database) as connection:
            counted = connection.execute(
                "SELECT topics.name, COUNT(*) FROM messages "
                "JOIN topics ON topics.id = messages.topic_id GROUP BY topics.name"
            ).fetchall()
        connection.close()
        for name, n in counted:
            seen[name] = seen.get(name, 0) + n
    for file in bag.glob("*.mcap"):
        with open(file, "rb") as stream:
            for _, channel, _ in make_reader(stream).iter_messages():
                seen[channel.topic] = seen.get(channel.topic, 0) + 1
    return seen


@pytest.mark.slow
@pytest.mark.parametrize(
    ("distro", "storage"), [(None, "sqlite3"), ("iron", "mcap"), ("jazzy", "sqlite3")]
)
def test_robotale_simulate_writes_each_distributions_bags(tmp_path, capsys, distro, storage):
    """The command a user runs, with and without --distro (Humble's metadata by default)."""
    from robotale.cli import main

    given = ["--distro", distro] if distro else []
    code = main(
        ["simulate", "agri", "--runs", "1", "--time-limit", "20", "--workers", "0", "--quiet",
         "--storage", storage, "--out", str(tmp_path / "runs"), *given]
    )  # fmt: skip
    assert code == 0, capsys.readouterr().err
    [bag] = [p.parent for p in (tmp_path / "runs").glob("*/metadata.yaml")]
    info = yaml.safe_load((bag / "metadata.yaml").read_text())["rosbag2_bagfile_information"]
    assert info["version"] == WRITES[distro or "humble"]
    listed = {
        e["topic_metadata"]["name"]: e["message_count"] for e in info["topics_with_message_count"]
    }
    seen = read_back(bag)
    assert seen == {topic: n for topic, n in listed.items() if n}
    assert sum(seen.values()) == info["message_count"] > 0
    assert {"/drone/tag", "/drone/odom"} <= set(seen)
