"""A live run as the pages read it: the tags ``robotale monitor`` stored so far, turned into
the canonical event log ``prepare`` makes of a recording (the same columns, order and event
ids), and served as a :class:`~robotale.results.replay.Replay` so the Mission and Timeline
pages answer on it as on a stored log while it grows.

The run's case is the live log's name. Each request looks at how many tags are stored; the
events are rebuilt only when that number grew.
"""

from __future__ import annotations

import math
import threading

import numpy as np
import pandas as pd
from neo4j import Driver

from robotale.ekg.connection import database
from robotale.ekg.live import live_tags
from robotale.eventlog import schema
from robotale.eventlog.prepare import tags_log
from robotale.fame_runtime.tags import tag_topic
from robotale.queries import cypher
from robotale.results.replay import Replay

_lock = threading.Lock()
#: live log name -> (tags it held, its replay): the last copy built of each
_built: dict[str, tuple[int, Replay]] = {}


def live_count(driver: Driver, name: str) -> int:
    """How many tags the live run ``name`` holds (0 when there is none)."""
    records, _, _ = driver.execute_query(cypher("live_count"), {"log": name}, database_=database())
    return int(records[0]["tags"])


def live_events(driver: Driver, name: str) -> pd.DataFrame:
    """The live run ``name`` as the canonical event log ``prepare`` makes of its recording:
    one event per tag, ordered by its stamp and, at equal stamps, in the order the monitor
    heard them (a robot's start before its own completion), its robot's tag topic and the
    tag's position there as its source; then enriched as :func:`tags_log` does."""
    tags = live_tags(driver, name)
    nanos = np.array([_nanoseconds(t.stamp) for t in tags], dtype=np.int64)
    robots = [t.robot for t in tags]
    frame = pd.DataFrame(
        {
            schema.CASE: name,
            schema.TIMESTAMP: pd.to_datetime(nanos, unit="ns", utc=True),
            schema.ACTIVITY: [t.activity for t in tags],
            schema.LIFECYCLE: [t.lifecycle for t in tags],
            schema.ROBOT: robots,
            schema.MSG_ID: [t.msg_id or None for t in tags],
            schema.MSG_ROLE: [t.msg_role or None for t in tags],
            schema.MSG_PAYLOAD: [t.payload or None for t in tags],
            schema.SOURCE_TOPIC: [tag_topic(r) for r in robots],
        }
    )
    frame[schema.SOURCE_INDEX] = frame.groupby(schema.ROBOT, sort=False).cumcount()
    frame = frame.iloc[np.argsort(nanos, kind="stable")].reset_index(drop=True)
    return tags_log(frame)


def _nanoseconds(stamp: float) -> int:
    """``stamp`` in whole nanoseconds, its seconds and its fraction apart (their product in one
    float would be off by hundreds of nanoseconds)."""
    seconds = math.floor(stamp)
    return seconds * 1_000_000_000 + round((stamp - seconds) * 1e9)


def live_replay(driver: Driver, name: str) -> Replay | None:
    """The live run ``name`` as it stands now, or None when no monitor stored one."""
    count = live_count(driver, name)
    if not count:
        return None
    with _lock:
        held = _built.get(name)
    if held is not None and held[0] == count:
        return held[1]
    replay = Replay(name, live_events(driver, name), {})
    with _lock:
        _built[name] = (count, replay)
    return replay
