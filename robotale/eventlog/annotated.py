"""A recording copied as an MCAP rosbag2 directory with what was mined from it added.

The copy holds every message of the recording with its bytes, topic, type and time unchanged,
and added topics that bag viewers read without a plugin:

- ``/robotale/<robot>/activity`` (``std_msgs/msg/String``): the robot's current activity from
  each start to its end (``idle`` between activities; with several open, the latest started),
  what Foxglove's and Lichtblick's State Transitions panel draws;
- ``/robotale/<robot>/activity_index`` (``std_msgs/msg/Int32``): the same as a number (0 idle,
  then the activities of the log in name order from 1), what PlotJuggler plots;
- ``/robotale/log`` (``rcl_interfaces/msg/Log``): one entry per message exchange and per
  finding, at its time, which their Log panels list.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import cast

import pandas as pd
from rosbags.interfaces import Connection, ConnectionExtRosbag2
from rosbags.rosbag2 import Reader, StoragePlugin, Writer
from rosbags.typesys import Stores, get_typestore
from rosbags.typesys.store import Typestore

from robotale.errors import InputError
from robotale.eventlog import schema
from robotale.eventlog.interfaces import normalized
from robotale.eventlog.rosbag import Bag

PREFIX = "/robotale"
LOG_TOPIC = f"{PREFIX}/log"
IDLE = "idle"
STRING, INT32, LOG = "std_msgs/msg/String", "std_msgs/msg/Int32", "rcl_interfaces/msg/Log"
#: rcl_interfaces/msg/Log levels
INFO, WARN = 20, 30
_NO_HASH = "RIHS01_" + "0" * 64


@dataclass(frozen=True)
class Entry:
    """One log entry: when (ns since the epoch), how grave, from what (``name``), and text."""

    time: int
    level: int
    name: str
    text: str


def activity_states(log: pd.DataFrame) -> pd.DataFrame:
    """Each robot's current activity after each of its events: time (ns), robot, activity
    (``idle`` when none is open), in log order. Only the start and end events count
    (``inprogress`` rows do not change the state)."""
    closing = {schema.COMPLETE, schema.ABORTED, schema.CANCELLED}
    rows = []
    open_by_robot: dict[str, list[str]] = {}
    times = log[schema.TIMESTAMP].dt.tz_convert("UTC").dt.as_unit("ns").astype("int64")
    for time, robot, activity, lifecycle in zip(
        times, log[schema.ROBOT].astype(str), log[schema.ACTIVITY].astype(str),
        log[schema.LIFECYCLE], strict=True,
    ):  # fmt: skip
        current = open_by_robot.setdefault(robot, [])
        if lifecycle == schema.START:
            current.append(activity)
        elif lifecycle in closing and activity in current:
            current.reverse()
            current.remove(activity)  # the latest open instance of it ends
            current.reverse()
        else:
            continue
        rows.append((int(time), robot, current[-1] if current else IDLE))
    return pd.DataFrame(rows, columns=["time", "robot", "activity"])


def write_annotated(
    bag: Bag, target: Path, states: pd.DataFrame, entries: Sequence[Entry], names: Sequence[str]
) -> dict[str, int]:
    """Copy the open ``bag`` to ``target`` (a new rosbag2 directory, MCAP storage) with the
    added topics; ``names`` are the activities in index order (index 1 first). Returns how many
    messages each added topic got."""
    if target.exists():
        raise InputError(f"{target} exists already: give --out a folder without it.")
    store = get_typestore(Stores.ROS2_HUMBLE)
    index = {name: k + 1 for k, name in enumerate(names)} | {IDLE: 0}
    written = {}
    target.parent.mkdir(parents=True, exist_ok=True)
    with Writer(target, version=9, storage_plugin=StoragePlugin.MCAP) as writer:
        copies = {c.id: _copy_connection(writer, bag, c) for c in bag.reader.connections}
        added: list[tuple[int, Connection, bytes]] = []
        for robot, rows in states.groupby("robot", sort=True):
            text = writer.add_connection(f"{PREFIX}/{robot}/activity", STRING, typestore=store)
            number = writer.add_connection(
                f"{PREFIX}/{robot}/activity_index", INT32, typestore=store
            )
            for time, activity in zip(rows["time"], rows["activity"], strict=True):
                added.append((int(time), text, _string(store, activity)))
                added.append((int(time), number, _int32(store, index.get(activity, -1))))
            written[text.topic] = written[number.topic] = len(rows)
        if entries:
            log = writer.add_connection(LOG_TOPIC, LOG, typestore=store)
            added += [(e.time, log, _log(store, e)) for e in entries]
            written[LOG_TOPIC] = len(entries)
        added.sort(key=lambda item: item[0])
        _merged_write(writer, bag.reader, copies, added)
    return written


def _merged_write(
    writer: Writer,
    reader: Reader,
    copies: dict[int, Connection],
    added: list[tuple[int, Connection, bytes]],
) -> None:
    """The recording's messages and the added ones (sorted) written in time order, an added
    message after the recording's of its instant; one comparison per message."""
    write, k, count = writer.write, 0, len(added)
    upcoming = added[0][0] if count else None
    for connection, time, raw in reader.messages():
        while upcoming is not None and upcoming < time:
            write(added[k][1], upcoming, added[k][2])
            k += 1
            upcoming = added[k][0] if k < count else None
        write(copies[connection.id], time, raw)
    for when, target, raw in added[k:]:
        write(target, when, raw)


def _copy_connection(writer: Writer, bag: Bag, connection: Connection) -> Connection:
    """The connection in the copy: its topic, type and QoS as recorded; its definition as the
    preparation resolved it (the bag's, or the distribution's or robotale's when it stores
    none), so viewers can decode it."""
    msgdef, digest = connection.msgdef.data, connection.digest
    kind = normalized(connection.msgtype)
    if kind in bag.typestore.fielddefs:
        msgdef, _ = bag.typestore.generate_msgdef(kind, ros_version=2)
    ext = cast(ConnectionExtRosbag2, connection.ext)  # a rosbag2 reader's connection
    qos = getattr(ext, "offered_qos_profiles", ())
    return writer.add_connection(
        connection.topic,
        connection.msgtype,
        msgdef=msgdef or "",
        rihs01=digest if str(digest).startswith("RIHS01_") else _NO_HASH,
        serialization_format=ext.serialization_format,
        offered_qos_profiles=qos,
    )


def _string(store: Typestore, text: str) -> bytes:
    return bytes(store.serialize_cdr(store.types[STRING](data=text), STRING))


def _int32(store: Typestore, value: int) -> bytes:
    return bytes(store.serialize_cdr(store.types[INT32](data=value), INT32))


def _log(store: Typestore, entry: Entry) -> bytes:
    stamp = store.types["builtin_interfaces/msg/Time"](
        sec=entry.time // 1_000_000_000, nanosec=entry.time % 1_000_000_000
    )
    message = store.types[LOG](
        stamp=stamp, level=entry.level, name=entry.name, msg=entry.text, file="", function="",
        line=0,
    )  # fmt: skip
    return bytes(store.serialize_cdr(message, LOG))
