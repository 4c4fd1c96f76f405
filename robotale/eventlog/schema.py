"""The canonical event log: the contract between eventlog, ekg, discovery and enhancement.

An event log is a pandas DataFrame with pm4py's column names, so pm4py functions take it as it
is. On disk (CSV) the columns carry the short names on the right. ``time:timestamp`` is always
timezone-aware. Perspective columns (``x``, ``y``, ``z``, ``battery`` and any other) keep their
own names in both forms.
"""

from __future__ import annotations

import re

import numpy as np
import pandas as pd

CASE = "case:concept:name"
ACTIVITY = "concept:name"
TIMESTAMP = "time:timestamp"
LIFECYCLE = "lifecycle:transition"
STATE = "lifecycle:state"
ROBOT = "robot"
ROBOT_TYPE = "robot_type"
MSG_ID = "msg_id"
MSG_ROLE = "msg_role"
MSG_PAYLOAD = "msg_payload"
#: the robots a message goes from and to, where the log says so (else the robots of its
#: send and receive events tell)
MSG_SENDER = "msg_sender"
MSG_RECEIVER = "msg_receiver"
#: where an event came from in its recording: the topic and the message's position on it
SOURCE_TOPIC = "source_topic"
SOURCE_INDEX = "source_index"
EVENT_ID = "event_id"
#: names one activity instance: the start and the complete event of one execution share it.
EXECUTION_ID = "execution_id"
X, Y, Z = "x", "y", "z"
BATTERY = "battery"

#: canonical (pm4py) name -> short name used in CSV files, in the order CSV files list them.
CSV_NAMES: dict[str, str] = {
    CASE: "case",
    TIMESTAMP: "time",
    ACTIVITY: "activity",
    LIFECYCLE: "lifecycle",
    STATE: "state",
    ROBOT: "robot",
    ROBOT_TYPE: "robot_type",
    MSG_ID: "msg_id",
    MSG_ROLE: "msg_role",
    MSG_PAYLOAD: "msg_payload",
    MSG_SENDER: "msg_sender",
    MSG_RECEIVER: "msg_receiver",
    SOURCE_TOPIC: "source_topic",
    SOURCE_INDEX: "source_index",
    X: "x",
    Y: "y",
    Z: "z",
    BATTERY: "battery",
    EVENT_ID: "event_id",
    EXECUTION_ID: "execution_id",
}

# Column names become Neo4j property keys: text that can never close a backtick-quoted name
# (no quotes, backticks, brackets or operators), as in `case:concept:name` or `robot id`.
_PROPERTY_NAME = re.compile(r"^[^\W\d][\w:. -]{0,99}$")


def is_property_name(name: object) -> bool:
    """True if ``name`` can be a column of a log and so a Neo4j property key."""
    return isinstance(name, str) and bool(_PROPERTY_NAME.match(name))


#: the columns every canonical log has (readers fill defaults where a source lacks them).
REQUIRED = (CASE, ACTIVITY, TIMESTAMP)

# Lifecycle values: a tag marks an activity's start or completion; TALE's enrichment adds
# ``inprogress`` rows (transition "none", state "inprogress") that carry continuous data.
START, COMPLETE, NONE = "start", "complete", "none"
#: outcomes other than success that end an activity (a ROS 2 action's aborted or cancelled goal)
ABORTED, CANCELLED = "aborted", "cancelled"
#: XES' standard transition for an aborted activity: robotale's engine ends an activity that
#: an interrupting boundary event or event sub-process cut short, or that was cancelled, with it
ATE_ABORT = "ate_abort"
#: the lifecycles that end an activity: its completion or an outcome
ENDINGS = frozenset({COMPLETE, ABORTED, CANCELLED, ATE_ABORT})
INPROGRESS = "inprogress"
SEND, RECEIVE = "send", "receive"


def to_csv_names(log: pd.DataFrame) -> pd.DataFrame:
    """The log with short CSV column names, known columns first in the documented order."""
    known = [c for c in CSV_NAMES if c in log.columns]
    others = [c for c in log.columns if c not in CSV_NAMES]
    return log[known + others].rename(columns=CSV_NAMES)


def from_csv_names(table: pd.DataFrame) -> pd.DataFrame:
    """The inverse of :func:`to_csv_names` (columns already canonical are left alone)."""
    short_to_long = {short: long for long, short in CSV_NAMES.items() if short != long}
    return table.rename(columns={c: short_to_long[c] for c in table.columns if c in short_to_long})


def message_roles(log: pd.DataFrame) -> pd.Series:
    """``send`` / ``receive`` / ``None`` per event.

    ``msg_role`` wins where it is set; otherwise the thesis' naming convention decides: a
    message activity ends in ``!`` when it sends and in ``?`` when it receives.
    """
    activity = log[ACTIVITY].astype("string")
    roles = np.full(len(log), None, dtype=object)
    roles[activity.str.endswith("!").fillna(False).to_numpy(bool)] = SEND
    roles[activity.str.endswith("?").fillna(False).to_numpy(bool)] = RECEIVE
    if MSG_ROLE in log.columns:
        # fillna: comparing pandas' NA (nullable string columns) with a role has no truth value
        explicit = log[MSG_ROLE].astype("string").fillna("").to_numpy(object)
        for role in (SEND, RECEIVE):
            roles[explicit == role] = role
    return pd.Series(roles, index=log.index, dtype=object, name=MSG_ROLE)
