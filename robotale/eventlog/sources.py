"""Which topics of a bag say what its robots did, besides tags: actions, states, BT logs.

:class:`Sources` is the choice (every part of it is a ``prepare`` option); :func:`propose`
makes one from what a bag holds (``--auto``); :func:`columns` says which fields to read and
:func:`activity_rows` turns the tables read into tag rows (:mod:`robotale.eventlog.activities`).
"""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from fnmatch import fnmatchcase
from typing import TYPE_CHECKING, Literal, overload

import numpy as np
import pandas as pd
from rosbags.interfaces import Nodetype

from robotale.errors import InputError
from robotale.eventlog import activities
from robotale.eventlog.activities import ACTION_STATUS, BT_FIELDS, INDEX, STATUS_TYPE
from robotale.eventlog.bagfiles import namespace
from robotale.eventlog.typesys import field_type

if TYPE_CHECKING:
    from rosbags.interfaces.typing import ConstValue, Typesdict

    from robotale.eventlog.rosbag import Bag  # typing only: a CSV does not import the reader

#: the field of a state topic read when none is named, in this order of preference
STATE_FIELDS = ("data", "state", "mode", "status", "value")
#: topic names ``--auto`` takes for state topics
STATE_NAMES = ("mode", "state")
_TEXT_OR_INTEGER = {"string", "int8", "uint8", "int16", "uint16", "int32", "uint32"}


@dataclass(frozen=True)
class Sources:
    """Topics that become activities other than the tags: globs, each ``None`` for none.

    ``states`` are ``GLOB`` or ``GLOB:FIELD`` strings.
    """

    actions: str | None = None
    states: Sequence[str] = field(default_factory=tuple)
    bt_logs: str | None = None

    def __bool__(self) -> bool:
        return bool(self.actions or self.states or self.bt_logs)

    def describe(self) -> list[str]:
        """The choice as the options that make it."""
        return [
            *([f"--actions {self.actions}"] if self.actions else []),
            *(f"--state-topic {spec}" for spec in self.states),
            *([f"--bt-log {self.bt_logs}"] if self.bt_logs else []),
        ]


def propose(bag: Bag) -> Sources:
    """What in ``bag`` looks like activities: action status topics, BT logs, mode/state topics."""
    actions = [t for t, kind in bag.topics.items() if kind == STATUS_TYPE]
    bt_logs = [t for t in bag.topics if t not in bag.unparsed and _bt_column(bag, t) is not None]
    states = [
        f"{topic}:{state}"
        for topic in bag.topics
        if topic.rstrip("/").rpartition("/")[2] in STATE_NAMES
        and topic not in bag.unparsed
        and (state := _state_field(bag, topic, None, strict=False))
    ]
    return Sources(ACTION_STATUS if actions else None, tuple(states), "|".join(bt_logs) or None)


def columns(bag: Bag, sources: Sources) -> dict[str, dict[str, str]]:
    """The fields to read, by topic, for ``sources``."""
    wanted: dict[str, dict[str, str]] = {}
    for topic in _matching(bag, sources.actions):
        if bag.topics[topic] == STATUS_TYPE:
            wanted[topic] = {"status_list": "status_list"}
    for spec in sources.states:
        glob, _, name = spec.partition(":")
        for topic in _matching(bag, glob):
            state = _state_field(bag, topic, name or None, strict=True)
            wanted[topic] = {**wanted.get(topic, {}), state: state}
    for topic in _matching(bag, sources.bt_logs):
        bag.fields(topic)  # a type without a definition is named as such, with the file to give
        column = _bt_column(bag, topic)
        if column is None:
            raise InputError(
                f"{bag.path}: {topic} ({bag.topics[topic]}) is not a behaviour-tree log: it has "
                f"neither {', '.join(BT_FIELDS)} nor a sequence of messages with them."
            )
        paths = [column] if column else list(BT_FIELDS)
        wanted[topic] = {**wanted.get(topic, {}), **{p: p for p in paths}}
    return wanted


def activity_rows(
    bag: Bag,
    tables: Mapping[str, pd.DataFrame],
    sources: Sources,
    case: str,
    end: pd.Timestamp,
    robot_of: Callable[[str], str] = namespace,
) -> list[pd.DataFrame]:
    """Tag rows of every source topic in ``tables`` (each table numbered by :data:`INDEX`);
    ``robot_of`` names the robot of a topic (default: its namespace)."""
    parts = []
    for topic in _matching(bag, sources.actions):
        if bag.topics[topic] == STATUS_TYPE:
            events = activities.goal_events(tables[topic], topic)
            parts.append(activities.rows(events, case, robot_of(topic), topic))
    for spec in sources.states:
        glob, _, name = spec.partition(":")
        for topic in _matching(bag, glob):
            state = _state_field(bag, topic, name or None, strict=True)
            names = _constant_names(bag, topic)
            events = activities.state_events(tables[topic], state, end, names)
            parts.append(activities.rows(events, case, robot_of(topic), topic))
    for topic in _matching(bag, sources.bt_logs):
        changes = activities.bt_changes(tables[topic], _bt_column(bag, topic) or None)
        events = activities.bt_events(changes)
        parts.append(activities.rows(events, case, robot_of(topic), topic))
    return parts


def numbered(table: pd.DataFrame) -> pd.DataFrame:
    """``table`` with each message's position on its topic."""
    return table.assign(**{INDEX: np.arange(len(table), dtype=np.int64)})


def _matching(bag: Bag, globs: str | None) -> list[str]:
    if not globs:
        return []
    return [t for t in bag.topics if any(fnmatchcase(t, g) for g in globs.split("|"))]


@overload
def _state_field(bag: Bag, topic: str, name: str | None, *, strict: Literal[True]) -> str: ...


@overload
def _state_field(
    bag: Bag, topic: str, name: str | None, *, strict: Literal[False]
) -> str | None: ...


def _state_field(bag: Bag, topic: str, name: str | None, *, strict: bool) -> str | None:
    """The field of a state topic: ``name``, else the first of :data:`STATE_FIELDS` that is text
    or an integer."""
    if topic in bag.unparsed and not strict:
        return None
    fields = bag.fields(topic)
    usable = [
        f
        for f in fields
        if field_type(bag.topics[topic], f, bag.typestore) in _TEXT_OR_INTEGER and "." not in f
    ]
    if name is not None:
        if name not in fields:
            raise InputError(
                f"{bag.path}: the state topic {topic} ({bag.topics[topic]}) has no field "
                f"{name!r}; its fields are {', '.join(fields)}."
            )
        return name
    chosen = next((f for f in STATE_FIELDS if f in usable), None)
    if chosen is None and strict:
        raise InputError(
            f"{bag.path}: the state topic {topic} ({bag.topics[topic]}) has no text or integer "
            f"field named {', '.join(STATE_FIELDS)}; name one as {topic}:FIELD."
        )
    return chosen


def _constant_names(bag: Bag, topic: str) -> dict[ConstValue, str]:
    """An enum message's values -> its constants' names, where each value has one name."""
    consts = bag.typestore.fielddefs[bag.topics[topic]][0]
    by_value: dict[ConstValue, list[str]] = {}
    for name, _, value in consts:
        by_value.setdefault(value, []).append(name)
    return {value: names[0] for value, names in by_value.items() if len(names) == 1}


def _bt_column(bag: Bag, topic: str) -> str | None:
    """``""`` if each message is a BT status change, the name of its sequence of changes if it
    holds one, ``None`` if it is neither."""
    definitions = bag.typestore.fielddefs
    msgtype = bag.topics[topic]
    if msgtype not in definitions:
        return None
    if _is_change(definitions, msgtype):
        return ""
    for name, desc in definitions[msgtype][1]:
        if desc[0] != Nodetype.SEQUENCE:
            continue
        item = desc[1][0]
        if item[0] == Nodetype.NAME and _is_change(definitions, item[1]):
            return name
    return None


def _is_change(definitions: Typesdict, msgtype: str) -> bool:
    if msgtype not in definitions:
        return False
    names = {name for name, _ in definitions[msgtype][1]}
    return set(BT_FIELDS) <= names
