"""A live run as the pages read it: the tags ``robotale monitor`` stored so far, turned into
the canonical event log ``prepare`` makes of a recording (the same columns, order and event
ids), and served as a :class:`~robotale.results.replay.Replay` so the Mission and Timeline
pages answer on it as on a stored log while it grows.

The run's case is the live log's name. The robots' positions (the map's trails and the state
API's pose) are the odometry samples the monitor kept, not columns of the events. Each request
looks at how many tags and samples are stored and reads only the new ones; the events are made
again only when tags came.
"""

from __future__ import annotations

import threading
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np
import pandas as pd
from neo4j import Driver

from robotale.ekg.connection import database
from robotale.ekg.live import Pose, live_poses, live_tags
from robotale.enhancement.mission import MissionRun
from robotale.enhancement.mission_state import Tracks
from robotale.eventlog import schema
from robotale.eventlog.prepare import tags_log
from robotale.eventlog.runs import robot_type
from robotale.fame_runtime.tags import Tag, tag_nanoseconds, tag_topic
from robotale.queries import cypher
from robotale.results.replay import Replay

_lock = threading.Lock()
#: live log name -> what a reader holds of it: its tags and samples, and the replay built
_kept: dict[str, _Kept] = {}


@dataclass
class LiveReplay(Replay):
    """A live run: its events, and its robots' positions from their odometry."""

    positions: Positions | None = None
    #: the runs as their events make them, kept while only the positions grow
    bare: dict[str, MissionRun] = field(default_factory=dict)

    def run(self, case: str) -> MissionRun:
        if case in self.runs:
            return self.runs[case]
        if case not in self.bare:
            self.bare[case] = super().run(case)
        run = self.bare[case]
        if self.positions is not None and self.positions.count:
            table, tracks = self.positions.since(run.start)
            run = run.with_positions(table, tracks)
        self.runs[case] = run
        return run


class Positions:
    """A live run's odometry samples as they come: the positions table (robot, s, x, y, z in
    time order, by robot where two share a time) and each robot's track, grown in place while
    the samples come in time order, made again whole when one comes late or the run's start
    moves."""

    def __init__(self) -> None:
        self.poses: list[Pose] = []
        self.at: float | None = None
        self.table = _positions([], 0.0)
        self.tracks = Tracks()

    @property
    def count(self) -> int:
        return len(self.poses)

    def add(self, poses: list[Pose]) -> None:
        self.poses += poses
        if self.at is None or not poses:
            return
        chunk = _positions(poses, self.at)
        ahead = self.table.empty or chunk["s"].min() > self.table["s"].iloc[-1]
        if ahead and self.tracks.extended(chunk):
            self.table = pd.concat([self.table, chunk], ignore_index=True)
        else:
            self.at = None  # made again whole when next asked

    def since(self, start: pd.Timestamp) -> tuple[pd.DataFrame, Tracks]:
        """The positions in seconds since ``start``, and their tracks."""
        at = start.timestamp()
        if at != self.at:
            self.at, self.table = at, _positions(self.poses, at)
            self.tracks = Tracks.of(self.table)
        return self.table, self.tracks


def _positions(poses: list[Pose], at: float) -> pd.DataFrame:
    """Where each robot was, by its odometry: robot, s (seconds since ``at``), x, y, z, in
    time order (by robot where two share a time)."""
    table = pd.DataFrame(
        {
            "robot": [p.robot for p in poses],
            "s": np.array([p.stamp for p in poses], dtype=float) - at,
            "x": np.array([p.x for p in poses], dtype=float),
            "y": np.array([p.y for p in poses], dtype=float),
            "z": np.array([p.z for p in poses], dtype=float),
        }
    )
    return table.sort_values(["s", "robot"], kind="stable").reset_index(drop=True)


@dataclass
class _Kept:
    """What a reader holds of a live run: every tag and sample read so far, and the replay
    built of them."""

    tags: list[Tag] = field(default_factory=list)
    positions: Positions = field(default_factory=Positions)
    replay: LiveReplay | None = None


def live_count(driver: Driver, name: str) -> int:
    """How many tags the live run ``name`` holds (0 when there is none)."""
    return live_counts(driver, name)[0]


def live_counts(driver: Driver, name: str) -> tuple[int, int]:
    """How many tags and odometry samples the live run ``name`` holds."""
    records, _, _ = driver.execute_query(cypher("live_count"), {"log": name}, database_=database())
    return int(records[0]["tags"]), int(records[0]["poses"])


def live_events(driver: Driver, name: str) -> pd.DataFrame:
    """The live run ``name`` as the canonical event log ``prepare`` makes of its recording
    (:func:`tags_events` of the tags stored for it)."""
    return tags_events(name, live_tags(driver, name))


def tags_events(name: str, tags: Sequence[Tag]) -> pd.DataFrame:
    """The tags heard of the live run ``name`` as the canonical event log ``prepare`` makes
    of its recording: one event per tag, ordered by its stamp and, at equal stamps, in the
    order they were heard (a robot's start before its own completion), its robot's tag topic
    and the tag's position there as its source; then enriched as :func:`tags_log` does."""
    nanos = np.array([tag_nanoseconds(t.stamp) for t in tags], dtype=np.int64)
    robots = [t.robot for t in tags]
    types = {robot: robot_type(robot) for robot in set(robots)}  # a few robots, many tags
    frame = pd.DataFrame(
        {
            schema.CASE: name,
            schema.TIMESTAMP: pd.to_datetime(nanos, unit="ns", utc=True),
            schema.ACTIVITY: [t.activity for t in tags],
            schema.LIFECYCLE: [t.lifecycle for t in tags],
            schema.ROBOT: robots,
            # a live run has no manifest: each robot's type from its name, as prepare's
            schema.ROBOT_TYPE: [types[r] for r in robots],
            schema.MSG_ID: [t.msg_id or None for t in tags],
            schema.MSG_ROLE: [t.msg_role or None for t in tags],
            schema.MSG_PAYLOAD: [t.payload or None for t in tags],
            schema.SOURCE_TOPIC: [tag_topic(r) for r in robots],
        }
    )
    frame[schema.SOURCE_INDEX] = frame.groupby(schema.ROBOT, sort=False).cumcount()
    frame = frame.iloc[np.argsort(nanos, kind="stable")].reset_index(drop=True)
    return tags_log(frame)


def live_replay(driver: Driver, name: str) -> Replay | None:
    """The live run ``name`` as it stands now, or None when no monitor stored one. Only what
    was stored since the last look is read (an index seek by number, whatever the run's
    length): the tags and samples kept are extended; the events are made again when tags
    came, the positions grown when only samples came."""
    with _lock:
        kept = _kept.get(name) or _Kept()
        new_tags = _since(live_tags, driver, name, kept.tags)
        new_poses = _since(live_poses, driver, name, kept.positions.poses)
        if new_tags is None or new_poses is None:  # a new run of that name began
            kept = _Kept()
            new_tags, new_poses = live_tags(driver, name), live_poses(driver, name)
        if not kept.tags and not new_tags:
            _kept.pop(name, None)
            return None
        _kept[name] = kept
        old = kept.replay
        if old is not None and not new_tags and not new_poses:
            return old
        kept.tags += new_tags
        kept.positions.add(new_poses)
        if old is None or new_tags:
            events = tags_events(name, kept.tags)
            kept.replay = LiveReplay(name, events, {}, positions=kept.positions)
        else:  # the same events: the runs they make are kept, their positions grown
            kept.replay = LiveReplay(name, old.events, {}, positions=kept.positions, bare=old.bare)
        return kept.replay


def _since(
    read: Callable[..., list[Any]], driver: Driver, name: str, held: list[Any]
) -> list[Any] | None:
    """What ``read`` finds stored after the ``held`` ones (numbered 1, 2, ... as stored), or
    None when the one held last is no longer stored under its number: a new run of that name
    began. The last one held is read again to tell."""
    if not held:
        return read(driver, name)
    found = read(driver, name, after=len(held) - 1)
    if not found or found[0] != held[-1]:
        return None
    return found[1:]
