"""What robotale knows of a rosbag2 recording without reading one: the folder's files, the
table columns every reader shares, and a topic's robot namespace.

Kept apart from :mod:`robotale.eventlog.rosbag` (the reader, with rosbags, MCAP and its
decompressors) so that a CSV's or a Parquet log's preparation, which shares the tag and
activity modules with recordings, does not import the reader: it was about a quarter of the
`robotale ingest` command's import time.
"""

from __future__ import annotations

from pathlib import Path

TIME = "time"
#: the column of a table holding when the bag recorded each message (ns since the epoch), when
#: asked for: the recording's order of messages from different topics
RECORDED = "_recorded"


def is_bag(path: Path) -> bool:
    """Whether ``path`` is a rosbag2 directory (it has a ``metadata.yaml``)."""
    return path.is_dir() and (path / "metadata.yaml").is_file()


def storage_files(path: Path) -> list[Path]:
    """The rosbag2 storage files (``.db3``, ``.mcap``) directly in ``path``."""
    return sorted([*path.glob("*.db3"), *path.glob("*.mcap")]) if path.is_dir() else []


def without_metadata(path: Path) -> str:
    """Why a folder without ``metadata.yaml`` is not read, and what would make it a bag."""
    storage = storage_files(path)
    if not storage:
        return f"{path} is not a rosbag2 directory (it has no metadata.yaml and no storage file)."
    return (
        f"{path} holds {storage[0].name}"
        + (f" and {len(storage) - 1} more storage file(s)" if len(storage) > 1 else "")
        + " but no metadata.yaml (was the recording interrupted?); `ros2 bag reindex "
        f"{path}` writes it from the storage files, then prepare the folder again."
    )


def namespace(topic: str) -> str:
    """The namespace of a topic: ``/tractor_1/odom`` -> ``tractor_1``; ``/odom`` -> ``""``.

    An action's topics are in the namespace of the action, not in the action's own:
    ``/r1/navigate_to_pose/_action/feedback`` -> ``r1``; a service's events in the service's:
    ``/r1/get_plan/_service_event`` -> ``r1``.
    """
    if "/_action/" in topic:
        topic = topic.rsplit("/_action/", 1)[0]
    topic = topic.removesuffix("/_service_event")
    return topic.strip("/").rpartition("/")[0]
