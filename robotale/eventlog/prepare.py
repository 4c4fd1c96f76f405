"""TALE preparation: rosbag2 recordings -> the canonical multi-perspective event log.

:func:`prepare` is the one function to call. It takes one rosbag2 directory or a folder of them
(a batch of runs: ``runs/agri/run_0001/`` ...), reads each bag's tag topics and the topics of
the chosen perspectives, and enriches the tags (:mod:`robotale.eventlog.enrich`). Every bag is one
case, named after its directory. The result is the DataFrame of :mod:`robotale.eventlog.schema`,
ready for the writers, pm4py or the EKG.

Bags recorded on real ROS 2 robots work too: the tag topics are a glob and the tag message's
field names are configurable (:class:`TagFields`); robotale's ``robotale_msgs/msg/Tag`` is the
default.
"""

from __future__ import annotations

import re
import warnings
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, fields, replace
from fnmatch import fnmatchcase
from pathlib import Path

import numpy as np
import pandas as pd
import yaml
from tqdm import tqdm

from robotale.errors import InputError
from robotale.eventlog import schema
from robotale.eventlog.enrich import (
    BUILTIN,
    Perspective,
    PreparationWarning,
    enrich,
    parse_perspective,
    robots_without_samples,
)
from robotale.eventlog.rosbag import TIME, Bag, is_bag, message_types, namespace
from robotale.fame_runtime.manifest import RunManifest, read_manifests

TAG_TOPICS = "/*/tag"
DEFAULT_PERSPECTIVES = ("odom", "battery")
#: each run's manifest by case id (the name ``robotale prepare`` imports; the manifest module
#: owns the file)
run_manifests = read_manifests
#: the robot of tags that name none, on a topic without a namespace (a single-robot bag).
DEFAULT_ROBOT = "robot"


@dataclass(frozen=True)
class TagFields:
    """Which field of the tag message holds what; an empty name means the message has none.

    ``activity`` and ``lifecycle`` are required. Without a ``robot`` field (or when it is empty)
    the robot is the tag topic's namespace.
    """

    activity: str = "activity"
    lifecycle: str = "lifecycle"
    robot: str = "robot"
    msg_id: str = "msg_id"
    msg_role: str = "msg_role"
    payload: str = "payload"

    @classmethod
    def parse(cls, specs: Sequence[str]) -> TagFields:
        """From ``KEY=FIELD`` strings, e.g. ``activity=action``, ``robot=`` (none)."""
        known = {f.name for f in fields(cls)}
        changes = {}
        for spec in specs:
            key, sep, value = spec.partition("=")
            if not sep or key.strip() not in known:
                keys = ", ".join(sorted(known))
                raise InputError(f"Tag field {spec!r} is not KEY=FIELD with KEY one of {keys}.")
            changes[key.strip()] = value.strip()
        return replace(cls(), **changes)


#: tag message field -> canonical log column
_TAG_COLUMNS = {
    "activity": schema.ACTIVITY,
    "lifecycle": schema.LIFECYCLE,
    "robot": schema.ROBOT,
    "msg_id": schema.MSG_ID,
    "msg_role": schema.MSG_ROLE,
    "payload": schema.MSG_PAYLOAD,
}
_LIFECYCLES = {schema.START, schema.COMPLETE, schema.NONE}


def prepare(
    source: str | Path,
    *,
    tags: str = TAG_TOPICS,
    tag_fields: TagFields | None = None,
    perspectives: Sequence[str | Perspective] = DEFAULT_PERSPECTIVES,
    rate: float = 1.0,
    msg_files: Sequence[str | Path] = (),
    bag_time: bool = False,
    progress: bool = False,
) -> pd.DataFrame:
    """The multi-perspective event log of a rosbag2 directory or of a folder of them.

    ``tags`` is the glob of the tag topics; ``perspectives`` are built-in names (``odom``,
    ``battery``), ``NAME=TOPIC_GLOB:FIELD`` strings or :class:`Perspective` objects; ``rate`` is
    the number of ``inprogress`` events per second of an activity (0: none); ``msg_files`` are
    ``.msg`` / ``.idl`` files (or folders) for types the bags do not define; ``bag_time`` uses
    recording times instead of message stamps; ``progress`` shows a bar on stderr.
    """
    chosen = [p if isinstance(p, Perspective) else parse_perspective(p) for p in perspectives]
    fields_ = tag_fields or TagFields()
    extra_types = message_types([Path(p) for p in msg_files])
    runs = find_runs(Path(source))
    globs = [tags, *(glob for p in chosen for glob in p.topic.split("|"))]
    with tqdm(
        total=sum(_message_count(run, globs) for run in runs),
        unit="msg",
        desc="prepare",
        disable=not progress,
        leave=False,
    ) as bar:
        parts = [_read_run(run, extra_types, tags, fields_, chosen, bag_time, bar) for run in runs]
    tag_rows = pd.concat([tag_part for tag_part, _ in parts], ignore_index=True)
    if tag_rows.empty:
        raise InputError(f"{source} has no tags: its topics matching {tags!r} hold no messages.")
    samples = {
        p.name: pd.concat([sample_parts[p.name] for _, sample_parts in parts], ignore_index=True)
        for p in chosen
    }
    _warn_missing_samples(tag_rows, samples, chosen)
    tag_rows[schema.ROBOT_TYPE] = _robot_types(tag_rows, read_manifests(runs))
    log = enrich(tag_rows, samples, rate=rate)
    return _canonical(log, chosen)


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
    for child in children:
        storage = [*child.glob("*.db3"), *child.glob("*.mcap")]
        if storage and not is_bag(child):
            raise InputError(
                f"{child} has {storage[0].name} but no metadata.yaml, so it is not a complete "
                "rosbag2 directory (was the recording interrupted?)."
            )
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


def _read_run(
    run: Path,
    extra_types: Mapping,
    tag_glob: str,
    tag_fields: TagFields,
    perspectives: Sequence[Perspective],
    bag_time: bool,
    bar: tqdm,
) -> tuple[pd.DataFrame, dict[str, pd.DataFrame]]:
    with Bag(run, extra_types) as bag:
        tag_topics = [t for t in bag.topics if fnmatchcase(t, tag_glob)]
        if not tag_topics:
            raise InputError(
                f"{run} has no tag topic matching {tag_glob!r}; its topics are "
                f"{', '.join(bag.topics) or 'none'} (name the tag topics with --tags)."
            )
        columns = {topic: _tag_columns(bag, topic, tag_fields) for topic in tag_topics}
        sample_topics = {
            p.name: [t for t in bag.topics if p.matches(t) and t not in columns]
            for p in perspectives
        }
        for p in perspectives:
            for topic in sample_topics[p.name]:
                columns[topic] = {**columns.get(topic, {}), **p.columns}
        tables = bag.tables(columns, bag_time=bag_time, progress=bar)
    tag_rows = pd.concat(
        [_tag_rows(tables[topic], topic, run) for topic in tag_topics], ignore_index=True
    )
    robots = sorted(set(tag_rows[schema.ROBOT]))
    samples = {
        p.name: _samples(run, [(t, tables[t]) for t in sample_topics[p.name]], p, robots)
        for p in perspectives
    }
    return tag_rows, samples


def _tag_columns(bag: Bag, topic: str, tag_fields: TagFields) -> dict[str, str]:
    available = set(bag.fields(topic))
    columns = {}
    for key, column in _TAG_COLUMNS.items():
        field = getattr(tag_fields, key)
        if field in available:
            columns[column] = field
        elif key in ("activity", "lifecycle"):
            raise InputError(
                f"{bag.path}: the tags on {topic} ({bag.topics[topic]}) have no field "
                f"{field!r} for the {key}; name it with --tag-field {key}=FIELD (its fields are "
                f"{', '.join(sorted(available))})."
            )
    return columns


def _tag_rows(table: pd.DataFrame, topic: str, run: Path) -> pd.DataFrame:
    rows = table.rename(columns={TIME: schema.TIMESTAMP})
    rows.insert(0, schema.CASE, run.name)
    given = rows[schema.LIFECYCLE].astype(str)
    rows[schema.LIFECYCLE] = given.str.strip().str.lower().replace("", schema.NONE)
    bad = ~rows[schema.LIFECYCLE].isin(_LIFECYCLES)
    if bad.any():
        at = rows.loc[bad, schema.TIMESTAMP].iloc[0].isoformat()
        raise InputError(
            f"{run}: a tag on {topic} at {at} has lifecycle {given[bad].iloc[0]!r}; "
            "expected start, complete or none."
        )
    fallback = namespace(topic) or DEFAULT_ROBOT
    robot = rows[schema.ROBOT].astype(str).str.strip() if schema.ROBOT in rows else None
    rows[schema.ROBOT] = fallback if robot is None else robot.replace("", fallback)
    for column in (schema.MSG_ID, schema.MSG_ROLE, schema.MSG_PAYLOAD):
        if column in rows:
            rows[column] = rows[column].astype(object).replace("", None)
    return rows


def _samples(
    run: Path,
    tables: Sequence[tuple[str, pd.DataFrame]],
    perspective: Perspective,
    robots: Sequence[str],
) -> pd.DataFrame:
    columns = [schema.CASE, schema.ROBOT, schema.TIMESTAMP, *perspective.columns]
    parts = []
    for topic, table in tables:
        part = table[[TIME, *perspective.columns]].rename(columns={TIME: schema.TIMESTAMP})
        for column, factor in (perspective.scale or {}).items():
            part[column] = part[column] * factor
        part[schema.CASE] = run.name
        part[schema.ROBOT] = namespace(topic) or _only_robot(run, topic, robots)
        parts.append(part[columns])
    if not parts:
        return pd.DataFrame({c: pd.Series(dtype=object) for c in columns}).astype(
            {schema.TIMESTAMP: "datetime64[ns, UTC]"}
        )
    return pd.concat(parts, ignore_index=True)


def _only_robot(run: Path, topic: str, robots: Sequence[str]) -> str:
    if len(robots) == 1:
        return robots[0]
    raise InputError(
        f"{run}: {topic} has no namespace, so it cannot be told which of the robots "
        f"({', '.join(robots)}) it belongs to; record it as /<robot>{topic}."
    )


def _robot_types(tags: pd.DataFrame, manifests: Mapping[str, RunManifest]) -> np.ndarray:
    """From each run's manifest (``robots``: name -> pool), else from the robot's name."""
    declared = {
        (case, name): _declared_type(value)
        for case, manifest in manifests.items()
        for name, value in (manifest.get("robots") or {}).items()
    }
    pairs = zip(tags[schema.CASE], tags[schema.ROBOT], strict=True)
    return np.array([declared.get(pair) or robot_type(pair[1]) for pair in pairs], dtype=object)


def _declared_type(value: object) -> str | None:
    if isinstance(value, Mapping):
        value = value.get("type") or value.get("pool")
    return str(value) if value else None


def _warn_missing_samples(
    tags: pd.DataFrame, samples: Mapping[str, pd.DataFrame], perspectives: Sequence[Perspective]
) -> None:
    for p in perspectives:
        if samples[p.name].empty:
            warnings.warn(
                f"No bag has samples of the {p.name} perspective ({p.topic}), so the log's "
                f"{', '.join(p.columns)} column(s) are empty.",
                PreparationWarning,
                stacklevel=3,
            )
            continue
        missing = robots_without_samples(tags, samples[p.name])
        if missing:
            warnings.warn(
                f"{len(missing)} robot(s) have tags but no {p.name} samples ({p.topic}): "
                f"{', '.join(missing[:5])}{', ...' if len(missing) > 5 else ''}.",
                PreparationWarning,
                stacklevel=3,
            )


def _canonical(log: pd.DataFrame, perspectives: Sequence[Perspective]) -> pd.DataFrame:
    """Known columns in the documented order, every perspective column present, event ids."""
    for column in [c for p in perspectives for c in p.columns]:
        if column not in log:
            log[column] = np.nan
    for column in (schema.MSG_ID, schema.MSG_ROLE, schema.MSG_PAYLOAD):
        if column not in log:
            log[column] = None
    # the written formats hold microseconds; the log should equal what is written
    log[schema.TIMESTAMP] = log[schema.TIMESTAMP].dt.floor("us")
    position = log.groupby(schema.CASE, sort=False).cumcount().astype(str)
    log[schema.EVENT_ID] = log[schema.CASE].astype(str) + ":" + position
    known = [c for c in schema.CSV_NAMES if c in log]
    return log[known + [c for c in log if c not in schema.CSV_NAMES]]


def _message_count(run: Path, globs: Sequence[str]) -> int:
    """How many messages of a bag the preparation reads, from its metadata alone."""
    try:
        text = (run / "metadata.yaml").read_text(encoding="utf-8")
        meta = yaml.load(text, Loader=getattr(yaml, "CSafeLoader", yaml.SafeLoader))
        topics = meta["rosbag2_bagfile_information"]["topics_with_message_count"]
        return sum(
            int(t["message_count"])
            for t in topics
            if any(fnmatchcase(t["topic_metadata"]["name"], g) for g in globs)
        )
    except (OSError, ValueError, KeyError, TypeError, yaml.YAMLError):
        return 0  # the bag's own reader explains what is wrong with it


__all__ = [
    "BUILTIN",
    "DEFAULT_PERSPECTIVES",
    "TAG_TOPICS",
    "TagFields",
    "find_runs",
    "is_recording",
    "prepare",
    "robot_type",
    "run_manifests",
]
