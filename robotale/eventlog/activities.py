"""Activities from what ROS 2 robots already publish, for bags without hand-placed tags.

Each source becomes tag rows (case, time, activity, lifecycle, robot, and where each event came
from: ``source_topic`` and ``source_index``, the message's position on its topic), which the
TALE enrichment then treats as it treats tags:

- ROS 2 actions: an ``<action>/_action/status`` topic (``action_msgs/msg/GoalStatusArray``)
  lists every goal with its status. Each goal is one activity instance named after the action,
  of the robot of the action's namespace: it starts when the server accepted it and ends with
  its outcome as the lifecycle (``complete``, ``aborted``, ``cancelled``), when the first status
  message says so.
- State topics: a string or enum field (``/*/mode``): each value is an activity from the
  message where it appears until the one where the next value does (a new activity ends the
  previous one); the last ends with the recording.
- Behaviour-tree transition logs (Nav2's ``nav2_msgs/msg/BehaviorTreeLog`` or any message with
  ``node_name``, ``previous_status`` and ``current_status``): a node is an activity from RUNNING
  until SUCCESS (complete), FAILURE (aborted) or IDLE (halted: cancelled).
- Tags with only starts, or plain events (:func:`implicit`): each tag starts an activity that
  the robot's next tag ends.
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
import pandas as pd

from robotale.eventlog import schema
from robotale.eventlog.bagfiles import TIME

SOURCE_TOPIC, SOURCE_INDEX = schema.SOURCE_TOPIC, schema.SOURCE_INDEX
#: the column of a topic's table that numbers its messages (added by the preparation)
INDEX = "_index"
ACTION_STATUS = "/*/_action/status"
STATUS_TYPE = "action_msgs/msg/GoalStatusArray"
#: action_msgs/msg/GoalStatus codes -> the lifecycle of the goal's activity they end it with
_GOAL_OUTCOMES = {4: schema.COMPLETE, 5: schema.CANCELLED, 6: schema.ABORTED}
_BT_OUTCOMES = {"SUCCESS": schema.COMPLETE, "FAILURE": schema.ABORTED, "IDLE": schema.CANCELLED}
BT_FIELDS = ("node_name", "previous_status", "current_status")
COLUMNS = [
    schema.CASE,
    schema.TIMESTAMP,
    schema.ACTIVITY,
    schema.LIFECYCLE,
    schema.ROBOT,
    schema.EXECUTION_ID,
    SOURCE_TOPIC,
    SOURCE_INDEX,
]


@dataclass(frozen=True)
class Event:
    """One activity event before it becomes a row."""

    time: pd.Timestamp
    activity: str
    lifecycle: str
    index: int
    execution: str | None = None
    #: made by the end of the recording rather than by a message (the last state's end)
    at_end: bool = False


def action_of(topic: str) -> tuple[str, str]:
    """``/r1/navigate_to_pose/_action/status`` -> (``r1``, ``navigate_to_pose``)."""
    before = topic.rsplit("/_action/", 1)[0].strip("/")
    robot, _, action = before.rpartition("/")
    return robot, action


def goal_events(table: pd.DataFrame, topic: str, column: str = "status_list") -> list[Event]:
    """One start and one outcome per goal of an action's status topic, in message order."""
    _, action = action_of(topic)
    started: set[str] = set()
    ended: set[str] = set()
    events = []
    for time, index, statuses in zip(table[TIME], table[INDEX], table[column], strict=True):
        for status in statuses:
            goal = bytes(np.asarray(status.goal_info.goal_id.uuid, dtype=np.uint8)).hex()
            if goal not in started:
                started.add(goal)
                accepted = _stamp(status.goal_info.stamp) or time
                events.append(Event(min(accepted, time), action, schema.START, index, goal))
            outcome = _GOAL_OUTCOMES.get(int(status.status))
            if outcome and goal not in ended:
                ended.add(goal)
                events.append(Event(time, action, outcome, index, goal))
    return events


def _stamp(stamp: Any) -> pd.Timestamp | None:  # a decoded builtin_interfaces/msg/Time
    nanos = int(stamp.sec) * 1_000_000_000 + int(stamp.nanosec)
    return pd.Timestamp(nanos, unit="ns", tz="UTC") if nanos > 0 else None


def state_events(
    table: pd.DataFrame, column: str, end: pd.Timestamp, names: Mapping[Any, str] | None = None
) -> list[Event]:
    """Each value of a state field an activity until the next value; the last until ``end``.

    ``names`` maps enum values to their constants' names (``2`` -> ``DOCKING``). An empty value
    is no activity: it only ends the previous one.
    """
    events: list[Event] = []
    current = None
    for time, index, value in zip(table[TIME], table[INDEX], table[column], strict=True):
        value = str((names or {}).get(value, value)).strip()
        if value == current:
            continue
        if current:
            events.append(Event(time, current, schema.COMPLETE, index))
        if value:
            events.append(Event(time, value, schema.START, index))
        current = value
    if current:
        last = events[-1]
        events.append(Event(max(end, last.time), current, schema.COMPLETE, last.index, None, True))
    return events


def bt_events(changes: Iterable[tuple[pd.Timestamp, int, Any]]) -> list[Event]:
    """Behaviour-tree nodes as activities, from (time, index, status change) in order.

    A change's own ``timestamp`` wins over the message time when it has one. A node that
    succeeds or fails without having been RUNNING is an instant activity; a reset to IDLE after
    an outcome is no event.
    """
    events = []
    for time, index, change in changes:
        stamp = getattr(change, "timestamp", None)
        when = (_stamp(stamp) if stamp is not None else None) or time
        node = str(change.node_name)
        before, after = (str(getattr(change, name)).upper() for name in BT_FIELDS[1:])
        if after == before:
            continue
        if after == "RUNNING" or (after in ("SUCCESS", "FAILURE") and before != "RUNNING"):
            events.append(Event(when, node, schema.START, index))
        if after in ("SUCCESS", "FAILURE") or (after == "IDLE" and before == "RUNNING"):
            events.append(Event(when, node, _BT_OUTCOMES[after], index))
    return events


def bt_changes(table: pd.DataFrame, column: str | None) -> list[tuple[pd.Timestamp, int, Any]]:
    """(time, index, change) of a log topic: ``column`` holds a sequence of changes per message,
    or each message is one change (``column`` None, its fields as columns)."""
    if column is not None:
        return [
            (time, index, change)
            for time, index, changes in zip(table[TIME], table[INDEX], table[column], strict=True)
            for change in changes
        ]
    fields = zip(*(table[name] for name in BT_FIELDS), strict=True)
    return [
        (time, index, _Change(*values))
        for time, index, values in zip(table[TIME], table[INDEX], fields, strict=True)
    ]


@dataclass(frozen=True)
class _Change:
    node_name: str
    previous_status: str
    current_status: str


def rows(events: Sequence[Event], case: str, robot: str, topic: str) -> pd.DataFrame:
    """Tag rows of ``events``."""
    return pd.DataFrame(
        {
            schema.CASE: case,
            schema.TIMESTAMP: pd.to_datetime([e.time for e in events], utc=True),
            schema.ACTIVITY: [e.activity for e in events],
            schema.LIFECYCLE: [e.lifecycle for e in events],
            schema.ROBOT: robot,
            schema.EXECUTION_ID: [e.execution for e in events],
            SOURCE_TOPIC: topic,
            SOURCE_INDEX: np.array([e.index for e in events], dtype=np.int64),
            AT_END: np.array([e.at_end for e in events], dtype=bool),
        },
        columns=[*COLUMNS, AT_END],
    )


#: a helper column of :func:`rows`: the event was made by the end of the recording
AT_END = "_at_end"
#: the position of a row in the order of :func:`in_order` (a helper column, dropped at the end)
SEQUENCE = "_sequence"


def in_order(parts: Sequence[pd.DataFrame], recorded: Mapping[str, np.ndarray]) -> pd.DataFrame:
    """The rows of ``parts`` as one table in the order of events of a run, numbered by
    :data:`SEQUENCE`.

    Events are ordered by time. At equal times the recording decides: the event of the
    message the bag recorded first comes first (``recorded``: topic -> each message's
    recording time), an event the end of the recording makes after every message's; the
    events one message gives keep the order they were made in, so an activity's start comes
    before its own completion. :func:`implicit` places the
    completions it adds by the same rule.
    """
    if not parts:
        return pd.DataFrame(columns=[*COLUMNS, SEQUENCE])
    when, rank = [], []
    for k, part in enumerate(parts):
        at = part[SOURCE_INDEX].to_numpy(np.int64)
        mine = np.zeros(len(part), dtype=np.int64)
        topics = part[SOURCE_TOPIC].to_numpy(object)
        for topic in pd.unique(topics):
            chosen = topics == topic
            mine[chosen] = np.asarray(recorded[topic], dtype=np.int64)[at[chosen]]
        if AT_END in part:
            mine[part[AT_END].to_numpy(bool)] = np.iinfo(np.int64).max
        when.append(mine)
        rank.append(np.full(len(part), k))
    rows = pd.concat(parts, ignore_index=True)
    rows = rows.drop(columns=[AT_END]) if AT_END in rows else rows
    times = rows[schema.TIMESTAMP].to_numpy("datetime64[ns]").view(np.int64)
    order = np.lexsort((np.concatenate(rank), np.concatenate(when), times), axis=0)
    if (order != np.arange(len(order))).any():
        rows = rows.take(order).reset_index(drop=True)
    return rows.assign(**{SEQUENCE: np.arange(len(rows), dtype=float)})


def implicit(
    rows: pd.DataFrame, ends: Mapping[str, pd.Timestamp], topics: Iterable[str] | None = None
) -> pd.DataFrame:
    """Tags whose activities end when the robot's next one starts.

    ``rows`` are in the order of :func:`in_order`; only those of ``topics`` (default: all)
    are tags. Every tag that is not a ``complete`` (or another outcome) starts an activity;
    one that its robot does not complete with its next tag is completed at that tag's time,
    just before it (so after its own start even at the same instant), the robot's last at
    the end of its run (``ends``: case -> time) or at its start if that is later. The added
    completes keep their start's source.
    """
    closing = schema.ENDINGS
    if SEQUENCE not in rows:
        rows = rows.assign(**{SEQUENCE: np.arange(len(rows), dtype=float)})
    chosen = set(topics) if topics is not None else None
    is_tag = (
        rows[SOURCE_TOPIC].isin(chosen).to_numpy(bool)
        if chosen is not None
        else np.ones(len(rows), bool)
    )
    lifecycle = rows[schema.LIFECYCLE].where(
        ~is_tag | rows[schema.LIFECYCLE].isin(closing), schema.START
    )
    rows = rows.assign(**{schema.LIFECYCLE: lifecycle})
    tags = rows[is_tag].sort_values([schema.CASE, schema.ROBOT, SEQUENCE], kind="stable")
    last = float(len(rows))
    added: list[dict[str, Any]] = []
    for (case, _), group in tags.groupby([schema.CASE, schema.ROBOT], sort=False):
        records = group.to_dict("records")
        for k, tag in enumerate(records):
            if tag[schema.LIFECYCLE] != schema.START:
                continue
            after = records[k + 1] if k + 1 < len(records) else None
            if after is not None and (
                after[schema.LIFECYCLE] in closing
                and after[schema.ACTIVITY] == tag[schema.ACTIVITY]
            ):
                continue
            close = dict(tag, **{schema.LIFECYCLE: schema.COMPLETE})
            if after is not None:
                close[schema.TIMESTAMP] = after[schema.TIMESTAMP]
                close[SEQUENCE] = after[SEQUENCE] - 0.5
            else:
                close[schema.TIMESTAMP] = max(ends[case], tag[schema.TIMESTAMP])
                close[SEQUENCE] = last + len(added)
            for column in (schema.MSG_ID, schema.MSG_ROLE, schema.MSG_PAYLOAD):
                close.pop(column, None)
            added.append(close)
    closes = pd.DataFrame(added, columns=rows.columns)
    merged = pd.concat([rows, closes], ignore_index=True) if len(closes) else rows
    return merged.sort_values(
        [schema.CASE, schema.TIMESTAMP, SEQUENCE], kind="stable", ignore_index=True
    )
