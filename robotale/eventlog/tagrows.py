"""Tags read from a bag: which field of the tag message holds what (:class:`TagFields`), the
columns they become, the robot of each topic, and a tag topic's rows as events.

The fields are those of the tag contract (:class:`robotale.fame_runtime.tags.Tag`); a bag
recorded elsewhere names them otherwise with ``--tag-field``.
"""

from __future__ import annotations

import warnings
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, fields, replace
from pathlib import Path
from typing import TYPE_CHECKING

import pandas as pd

from robotale.errors import InputError
from robotale.eventlog import schema
from robotale.eventlog.activities import INDEX
from robotale.eventlog.bagfiles import TIME, namespace
from robotale.eventlog.enrich import PreparationWarning
from robotale.eventlog.lifecycles import lifecycles

if TYPE_CHECKING:  # the reader only types a bag here: a CSV's preparation does not import it
    from robotale.eventlog.rosbag import Bag

#: the robot of tags that name none, on a topic without a namespace (a single-robot bag).
DEFAULT_ROBOT = "robot"


@dataclass(frozen=True)
class TagFields:
    """Which field of the tag message holds what; an empty name means the message has none.

    ``activity`` is required. Without a ``lifecycle`` field each tag is one event (or, with
    ``lifecycle="implicit"``, an activity until the robot's next tag). Without a ``robot`` field
    (or when it is empty) the robot is the tag topic's namespace.
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


#: the tag fields whose log column has another name; the others keep the field's name
_RENAMED = {
    "activity": schema.ACTIVITY,
    "lifecycle": schema.LIFECYCLE,
    "payload": schema.MSG_PAYLOAD,
}


#: tag message field -> canonical log column, for every field of the tag contract (in the
#: order of :class:`TagFields`, which names the same fields: the activity's first)
_TAG_COLUMNS = {f.name: _RENAMED.get(f.name, f.name) for f in fields(TagFields)}


def warn_foreign(bag: Bag, columns: Mapping[str, Mapping[str, str]]) -> None:
    """What the preparation read around in a bag robotale did not write."""
    skipped = [t for t in bag.unparsed if t not in columns]
    if skipped:
        warnings.warn(
            f"{bag.path}: the message definitions stored for {', '.join(skipped)} cannot be "
            "parsed; those topics were not read.",
            PreparationWarning,
            stacklevel=4,
        )
    mismatched = [t for t in bag.qos_mismatch if t in columns]
    if mismatched:
        warnings.warn(
            f"{bag.path}: metadata.yaml describes {', '.join(mismatched)} with other QoS "
            "profiles (or type hashes) than its storage does; their messages were read from the "
            "storage.",
            PreparationWarning,
            stacklevel=4,
        )


def tag_columns(bag: Bag, topic: str, tag_fields: TagFields) -> dict[str, str]:
    available = set(bag.fields(topic))
    columns = {}
    for key, column in _TAG_COLUMNS.items():
        field = getattr(tag_fields, key)
        if field in available:
            columns[column] = field
        elif key == "activity" or (key == "lifecycle" and field):
            raise InputError(
                f"{bag.path}: the tags on {topic} ({bag.topics[topic]}) have no field "
                f"{field!r} for the {key}; name it with --tag-field {key}=FIELD (its fields are "
                f"{', '.join(sorted(available))}"
                + ("; --tag-field lifecycle= if it has none)." if key == "lifecycle" else ").")
            )
    return columns


def robot_of_topics(bag: Bag, given: str | None) -> Callable[[str], str]:
    """The robot of a topic's tags and activities: its namespace; for a topic without one,
    ``--robot``, else the bag's only namespace, else :data:`DEFAULT_ROBOT`, said once per
    topic as a warning (a wrong robot would silently split or merge robots)."""
    spaces = sorted({namespace(t).split("/")[0] for t in bag.topics} - {""})
    told: set[str] = set()

    def robot_of(topic: str) -> str:
        found = namespace(topic)
        if found:
            return found
        if given:
            return given
        robot, why = (
            (spaces[0], "the only namespace of its topics")
            if len(spaces) == 1
            else (DEFAULT_ROBOT, "the bag's topics have no namespace" if not spaces else
                  f"the bag's topics have {len(spaces)} namespaces")
        )  # fmt: skip
        if topic not in told:
            told.add(topic)
            warnings.warn(
                f"{bag.path}: {topic} ({bag.topics[topic]}) has no namespace, so its "
                f"activities are of robot {robot!r} ({why}); name the robot with --robot NAME.",
                PreparationWarning,
                stacklevel=2,
            )
        return robot

    return robot_of


def topic_rows(
    table: pd.DataFrame,
    topic: str,
    run: Path,
    tag_fields: TagFields,
    lifecycle: str | None,
    robot_of: Callable[[str], str],
) -> pd.DataFrame:
    """A tag topic's rows as events of the run: its case, topic, lifecycle and robot."""
    rows = table.rename(columns={TIME: schema.TIMESTAMP, INDEX: schema.SOURCE_INDEX})
    rows.insert(0, schema.CASE, run.name)
    rows[schema.SOURCE_TOPIC] = topic
    rows = without_empty_activities(rows, topic, run, tag_fields)
    rows[schema.LIFECYCLE] = lifecycles(rows, topic, run, lifecycle)
    robot = rows[schema.ROBOT].astype(str).str.strip() if schema.ROBOT in rows else None
    defaulted = robot is None or (robot == "").any()
    fallback = robot_of(topic) if defaulted and len(rows) else namespace(topic)
    rows[schema.ROBOT] = fallback if robot is None else robot.replace("", fallback)
    for column in (schema.MSG_ID, schema.MSG_ROLE, schema.MSG_PAYLOAD):
        if column in rows:
            rows[column] = rows[column].astype(object).replace("", None)
    return rows


def without_empty_activities(
    rows: pd.DataFrame, topic: str, run: Path, tag_fields: TagFields
) -> pd.DataFrame:
    """The tags that name an activity; the others are left out with a warning."""
    empty = rows[schema.ACTIVITY].astype(str).str.strip() == ""
    if empty.any():
        warnings.warn(
            f"{run}: {int(empty.sum())} tag(s) on {topic} have an empty activity (field "
            f"{tag_fields.activity!r}) and were left out; name the field holding the activity "
            "with --tag-field activity=FIELD.",
            PreparationWarning,
            stacklevel=5,
        )
    return rows[~empty].reset_index(drop=True)
