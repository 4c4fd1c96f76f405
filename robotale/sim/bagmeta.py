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
Jazzy) into what the distribution itself writes, in metadata.yaml and in a sqlite3 bag's own
``metadata`` table.
"""

from __future__ import annotations

import sqlite3
from pathlib import Path

import yaml
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
