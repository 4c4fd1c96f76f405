"""The runs of a recording: which folders are rosbag2 directories, what their metadata counts,
and the robots' types the runs declare."""

from __future__ import annotations

import re
from collections.abc import Mapping, Sequence
from fnmatch import fnmatchcase
from pathlib import Path

import numpy as np
import pandas as pd
import yaml

from robotale.errors import InputError
from robotale.eventlog import schema
from robotale.eventlog.bagfiles import is_bag, storage_files, without_metadata
from robotale.fame_runtime.manifest import RunManifest


def is_recording(path: str | Path) -> bool:
    """Whether ``path`` is what :func:`prepare` reads: a bag directory or a folder of them."""
    path = Path(path)
    return is_bag(path) or (path.is_dir() and any(is_bag(c) for c in path.iterdir() if c.is_dir()))


def find_runs(source: Path) -> list[Path]:
    """The bag directories of ``source``: itself, or its sub-directories that are bags."""
    if not source.exists():
        raise InputError(f"{source} does not exist.")
    if is_bag(source):
        return [source]
    if not source.is_dir():
        raise InputError(f"{source} is not a rosbag2 directory (a folder with metadata.yaml).")
    children = sorted(child for child in source.iterdir() if child.is_dir())
    for child in [source, *children]:
        if storage_files(child) and not is_bag(child):
            raise InputError(without_metadata(child))
    runs = [child for child in children if is_bag(child)]
    if not runs:
        raise InputError(
            f"{source} is not a rosbag2 directory (it has no metadata.yaml) and holds none."
        )
    return runs


def robot_type(robot: str) -> str:
    """A robot's type from its name when nothing says otherwise: ``tractor_1`` -> ``Tractor``."""
    base = re.sub(r"[_\-]?\d+$", "", robot) or robot
    return base[:1].upper() + base[1:]


def robot_types(tags: pd.DataFrame, manifests: Mapping[str, RunManifest]) -> np.ndarray:
    """From each run's manifest (``robots``: name -> pool), else from the robot's name."""
    declared = {
        (case, name): declared_type(value)
        for case, manifest in manifests.items()
        for name, value in (manifest.get("robots") or {}).items()
    }
    pairs = zip(tags[schema.CASE], tags[schema.ROBOT], strict=True)
    return np.array([declared.get(pair) or robot_type(pair[1]) for pair in pairs], dtype=object)


def declared_type(value: object) -> str | None:
    if isinstance(value, Mapping):
        value = value.get("type") or value.get("pool")
    return str(value) if value else None


def message_count(run: Path, globs: Sequence[str]) -> int:
    """How many messages of a bag the preparation reads, from its metadata alone."""
    return sum(message_counts(run, globs).values())


def message_counts(run: Path, globs: Sequence[str]) -> dict[str, int]:
    """The message count of each topic of a bag matching ``globs``, from its metadata."""
    try:
        text = (run / "metadata.yaml").read_text(encoding="utf-8")
        meta = yaml.load(text, Loader=getattr(yaml, "CSafeLoader", yaml.SafeLoader))
        topics = meta["rosbag2_bagfile_information"]["topics_with_message_count"]
        return {
            str(t["topic_metadata"]["name"]): int(t["message_count"])
            for t in topics
            if any(fnmatchcase(t["topic_metadata"]["name"], g) for g in globs)
        }
    except (OSError, ValueError, KeyError, TypeError, yaml.YAMLError):
        return {}  # the bag's own reader explains what is wrong with it
