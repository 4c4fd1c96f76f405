"""rosbag2 metadata that a given ROS 2 distribution's ``ros2 bag`` reads.

rosbags writes metadata version 8 or 9. Each distribution's reader
(``rosbag2_storage``'s YAML decoding) expects its own fields:

- Humble (metadata version 5): ``offered_qos_profiles`` is a string holding YAML; no
  ``type_description_hash``, ``custom_data`` or ``ros_distro``.
- Iron (version 7): as Humble, plus ``custom_data`` (a map) and ``type_description_hash``.
- Jazzy (version 9): ``offered_qos_profiles`` is a YAML list of maps, plus ``ros_distro``.

A reader decodes the fields of the version a file states, so a file stating a newer version
than the distribution's own (9 read by Humble: the QoS list where a string is expected) fails.
:func:`for_distro` rewrites the metadata rosbags wrote (version 8 for Humble and Iron, 9 for
Jazzy) into what the distribution itself writes, in metadata.yaml, in a sqlite3 bag's own
``metadata`` table and in an MCAP file's ``rosbag2`` metadata record.

That record is what rosbag2's MCAP plugin (``rosbag2_storage_mcap/src/mcap_storage.cpp``)
writes: Humble's and Iron's ``{ROS_DISTRO: <distro>}`` (``ensure_rosdistro_metadata_added``),
Jazzy's ``{serialized_metadata: <the bag's metadata as YAML>}`` (``update_metadata``). rosbags
writes the latter whatever the version. Humble's and Iron's plugins never read the record;
Jazzy's ``read_metadata`` decodes ``serialized_metadata`` (even with a metadata.yaml next to
it: ``SequentialReader::seek`` asks the storage for its metadata) and falls back to version 8
without it.
"""

from __future__ import annotations

import sqlite3
from pathlib import Path

import yaml
from mcap.reader import make_reader
from mcap.writer import CompressionType
from mcap.writer import Writer as McapWriter
from rosbags.interfaces import (
    Qos,
    QosDurability,
    QosHistory,
    QosLiveliness,
    QosReliability,
    QosTime,
)

#: distribution -> the metadata version its rosbag2 writes (and the newest it reads)
VERSIONS = {"humble": 5, "iron": 7, "jazzy": 9}
#: the oldest supported LTS, so bags are readable by every supported distribution's reader
DEFAULT_DISTRO = "humble"
_NO_TIME = QosTime(0, 0)
#: what an rclcpp publisher with default settings offers (keep last 10, reliable, volatile)
DEFAULT_QOS = Qos(
    QosHistory.KEEP_LAST,
    10,
    QosReliability.RELIABLE,
    QosDurability.VOLATILE,
    _NO_TIME,
    _NO_TIME,
    QosLiveliness.AUTOMATIC,
    _NO_TIME,
    False,
)


def writer_version(distro: str) -> int:
    """The version to ask rosbags' writer for: 9 where the QoS is a list, else 8."""
    return 9 if VERSIONS[check(distro)] >= 9 else 8


def check(distro: str) -> str:
    if distro not in VERSIONS:
        raise ValueError(f"unknown ROS 2 distribution {distro!r}: one of {', '.join(VERSIONS)}")
    return distro


def for_distro(bag: Path, distro: str) -> None:
    """Rewrite ``bag``'s metadata (written by rosbags) as ``distro``'s rosbag2 writes it."""
    path = bag / "metadata.yaml"
    document = yaml.safe_load(path.read_text(encoding="utf-8"))
    info = _converted(document["rosbag2_bagfile_information"], check(distro))
    document["rosbag2_bagfile_information"] = info
    path.write_text(yaml.safe_dump(document, sort_keys=False), encoding="utf-8")
    for database in bag.glob("*.db3"):
        _store_in_database(database, info)
    for mcap in bag.glob("*.mcap"):
        _store_in_mcap(mcap, info, distro)


def _converted(info: dict, distro: str) -> dict:
    version = VERSIONS[distro]
    info = {**info, "version": version}
    for entry in info["topics_with_message_count"]:
        topic = entry["topic_metadata"]
        if version < 7:
            topic.pop("type_description_hash", None)
        if version < 9 and not isinstance(topic.get("offered_qos_profiles"), str):
            topic["offered_qos_profiles"] = yaml.safe_dump(topic["offered_qos_profiles"] or [])
    if version < 6:
        info.pop("custom_data", None)
    elif not info.get("custom_data"):
        info["custom_data"] = {}
    if version < 8:
        info.pop("ros_distro", None)
    else:
        info["ros_distro"] = distro
    return info


def _store_in_database(database: Path, info: dict) -> None:
    """The copy of the metadata a sqlite3 bag keeps (schema 4 and later), kept the same."""
    with sqlite3.connect(database) as connection:
        tables = {row[0] for row in connection.execute("SELECT name FROM sqlite_master")}
        if "metadata" in tables:
            connection.execute(
                "UPDATE metadata SET metadata_version = ?, metadata = ?",
                (info["version"], yaml.safe_dump(info, sort_keys=False).strip()),
            )
    connection.close()


def mcap_record(info: dict, distro: str) -> dict[str, str]:
    """The ``rosbag2`` metadata record ``distro``'s MCAP plugin writes into each file."""
    if VERSIONS[distro] < 9:
        return {"ROS_DISTRO": distro}
    return {"serialized_metadata": yaml.safe_dump(info, sort_keys=False)}


def _store_in_mcap(file: Path, info: dict, distro: str) -> None:
    """``file`` written again with ``distro``'s ``rosbag2`` record in place of rosbags' (the
    record sits before the summary that indexes it, so the file is copied, not patched)."""
    copy = file.with_name(f".{file.name}.part")
    try:
        _copy_mcap(file, copy, mcap_record(info, distro))
        copy.replace(file)
    finally:
        copy.unlink(missing_ok=True)


def _copy_mcap(file: Path, copy: Path, record: dict[str, str]) -> None:
    with file.open("rb") as source, copy.open("wb") as target:
        reader = make_reader(source)
        summary = reader.get_summary()
        compressed = any(chunk.compression for chunk in summary.chunk_indexes)
        writer = McapWriter(
            target, compression=CompressionType.ZSTD if compressed else CompressionType.NONE
        )
        header = reader.get_header()
        writer.start(profile=header.profile, library=header.library)
        schemas = {
            key: writer.register_schema(schema.name, schema.encoding, schema.data)
            for key, schema in summary.schemas.items()
        }
        channels = {
            key: writer.register_channel(
                channel.topic, channel.message_encoding, schemas.get(channel.schema_id, 0),
                channel.metadata,
            )
            for key, channel in summary.channels.items()
        }  # fmt: skip
        for _, channel, message in reader.iter_messages(log_time_order=False):
            writer.add_message(
                channels[channel.id], message.log_time, message.data, message.publish_time,
                message.sequence,
            )  # fmt: skip
        for metadata in reader.iter_metadata():
            if metadata.name != "rosbag2":
                writer.add_metadata(metadata.name, metadata.metadata)
        writer.add_metadata("rosbag2", record)
        writer.finish()
