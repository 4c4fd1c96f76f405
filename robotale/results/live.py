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
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np
import pandas as pd
from neo4j import Driver

from robotale.discovery.instances import FINISHED, START_TIMESTAMP, activity_instances
from robotale.ekg.connection import database
from robotale.ekg.live import Pose, live_since, live_tags
from robotale.enhancement.mission import MissionRun, carrying, lone_run, open_from, run_events
from robotale.enhancement.mission_state import Tracks
from robotale.enhancement.timeline import case_messages
from robotale.eventlog import schema
from robotale.eventlog.enrich import pair_activities
from robotale.eventlog.prepare import tags_log
from robotale.eventlog.runs import robot_type
from robotale.fame_runtime.tags import Tag, tag_nanoseconds, tag_topic
from robotale.queries import cypher
from robotale.results.replay import Replay

#: a stamp no end has: the start is still open
NEVER = np.iinfo(np.int64).max
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
    time order, by robot where two share a time) and each robot's track. Both grow in place:
    the table's columns are arrays with room to grow (doubled when full), the table a view of
    their filled part, so a look that found samples costs what it found, not the run's length
    (a look waiting for tags finds samples at each of its checks). Samples of different robots
    come a little out of time order (robots publish from several processes, and the monitor
    stores them as they arrive, a batch every tenth of a second): a batch earlier than the
    last rows held is merged into the rows from its first time on only. Made again whole when
    a robot's own sample comes late or the run's start moves."""

    def __init__(self) -> None:
        self.poses: list[Pose] = []
        self.at: float | None = None
        #: how many samples the columns hold, and the columns (room for more)
        self.size = 0
        self.columns = _Columns()
        self.tracks = Tracks()
        self._table: pd.DataFrame | None = None
        #: how many rows of the columns the tables handed out cover: a run made earlier
        #: holds its table, so those rows are never written again in place
        self.shown = 0

    @property
    def count(self) -> int:
        return len(self.poses)

    @property
    def table(self) -> pd.DataFrame:
        """The positions held, a view of the columns' filled part (made once per size)."""
        if self._table is None or len(self._table) != self.size:
            self._table = self.columns.view(self.size)
            self.shown = max(self.shown, self.size)
        return self._table

    def add(self, poses: list[Pose]) -> None:
        self.poses += poses
        if self.at is None or not poses:
            return
        chunk = _Columns.of(poses, self.at)
        if not self.tracks.extended(chunk.view(len(poses))):
            self.at = None  # a robot's own sample came late: made again whole when next asked
            return
        # the rows held from the batch's first time on (none while samples come in order)
        # are merged with it; those before stay as they are
        first = int(np.searchsorted(self.columns.s[: self.size], chunk.s[0], side="left"))
        if first < self.size:
            chunk = _Columns.merged(self.columns.part(first, self.size), chunk)
            if first < self.shown:  # rows a table handed out shows: written to new arrays
                self.columns, self.shown = self.columns.copied(first), 0
        self.columns.put(first, chunk)
        self.size = first + len(chunk.s)
        self._table = None

    def since(self, start: pd.Timestamp) -> tuple[pd.DataFrame, Tracks]:
        """The positions in seconds since ``start``, and their tracks."""
        at = start.timestamp()
        if at != self.at:
            self.at, self.columns = at, _Columns.of(self.poses, at)
            self.size, self._table, self.shown = len(self.poses), None, 0
            self.tracks = Tracks.of(self.table)
        return self.table, self.tracks


@dataclass
class _Columns:
    """The positions table's columns as arrays: robot (objects: a view of them is a column
    as it is, where a column of strings would be copied), s, x, y, z."""

    robot: np.ndarray = field(default_factory=lambda: np.empty(0, dtype=object))
    s: np.ndarray = field(default_factory=lambda: np.empty(0))
    x: np.ndarray = field(default_factory=lambda: np.empty(0))
    y: np.ndarray = field(default_factory=lambda: np.empty(0))
    z: np.ndarray = field(default_factory=lambda: np.empty(0))

    NAMES = ("robot", "s", "x", "y", "z")

    @classmethod
    def of(cls, poses: list[Pose], at: float) -> _Columns:
        """``poses`` in time order (by robot where two share a time), s in seconds since
        ``at``."""
        s = np.array([p.stamp for p in poses], dtype=float) - at
        order = sorted(range(len(poses)), key=lambda i: (s[i], poses[i].robot))
        chosen = [poses[i] for i in order]
        return cls(
            np.array([p.robot for p in chosen], dtype=object),
            s[order] if len(order) else s,
            np.array([p.x for p in chosen], dtype=float),
            np.array([p.y for p in chosen], dtype=float),
            np.array([p.z for p in chosen], dtype=float),
        )

    @classmethod
    def merged(cls, held: _Columns, chunk: _Columns) -> _Columns:
        """The rows ``held`` and those of ``chunk`` (heard after them), each in order, in
        one order: by time, then robot, then as heard (as :meth:`of` orders them all)."""
        s = np.concatenate([held.s, chunk.s])
        robot = np.concatenate([held.robot, chunk.robot])
        order = sorted(range(len(s)), key=lambda i: (s[i], robot[i]))
        return cls(
            robot[order],
            s[order],
            np.concatenate([held.x, chunk.x])[order],
            np.concatenate([held.y, chunk.y])[order],
            np.concatenate([held.z, chunk.z])[order],
        )

    def part(self, first: int, end: int) -> _Columns:
        """Rows ``first`` to ``end`` (copies: the rows are written again after)."""
        return _Columns(*(getattr(self, n)[first:end].copy() for n in _Columns.NAMES))

    def copied(self, size: int) -> _Columns:
        """New arrays of the same room holding the first ``size`` rows."""
        fresh = _Columns()
        for name in _Columns.NAMES:
            held = getattr(self, name)
            grown = np.empty(len(held), dtype=held.dtype)
            grown[:size] = held[:size]
            setattr(fresh, name, grown)
        return fresh

    def put(self, at: int, chunk: _Columns) -> None:
        """Write ``chunk`` from row ``at`` on, the room doubled when it does not fit."""
        end = at + len(chunk.s)
        if end > len(self.s):
            room = max(2 * len(self.s), end, 1024)
            for name in _Columns.NAMES:
                grown = np.empty(room, dtype=getattr(self, name).dtype)
                grown[:at] = getattr(self, name)[:at]
                setattr(self, name, grown)
        for name in _Columns.NAMES:
            getattr(self, name)[at:end] = getattr(chunk, name)

    def view(self, size: int) -> pd.DataFrame:
        """The first ``size`` rows as a table, not copied (later rows are written past them
        only, so the view stays as it was made)."""
        return pd.DataFrame(
            {
                "robot": pd.Series(self.robot[:size], dtype=object, copy=False),
                "s": self.s[:size],
                "x": self.x[:size],
                "y": self.y[:size],
                "z": self.z[:size],
            },
            copy=False,
        )


def _positions(poses: list[Pose], at: float) -> pd.DataFrame:
    """Where each robot was, by its odometry: robot, s (seconds since ``at``), x, y, z, in
    time order (by robot where two share a time); the robot column of objects, as
    :class:`Positions` holds it."""
    return _Columns.of(poses, at).view(len(poses)).copy()


@dataclass
class _Kept:
    """What a reader holds of a live run: every tag and sample read so far, the events and
    activity instances made of the tags, and the replay built of them."""

    made: LiveEvents = field(default_factory=lambda: LiveEvents())
    positions: Positions = field(default_factory=Positions)
    replay: LiveReplay | None = None
    #: which of the run's events the run's messages were read of (:func:`carrying`), and
    #: what :func:`case_messages` read of them
    carried: np.ndarray = field(default_factory=lambda: np.empty(0, dtype=bool))
    told: tuple[pd.DataFrame, set[str]] | None = None
    #: how many times the run's events were made (the first look's and each one that
    #: found tags), for :func:`live_builds`
    builds: int = 0

    @property
    def tags(self) -> list[Tag]:
        return self.made.tags

    def grow(self, name: str, tags: list[Tag]) -> tuple[pd.DataFrame, MissionRun]:
        """Take the newly read ``tags`` in; the events (:meth:`LiveEvents.add`) and the run
        they make, the run's tables before the events made again taken over from the last
        look's run."""
        events, found, unchanged, kept = self.made.add(name, tags)
        events_of_run = run_events(events, name)
        run = lone_run(events_of_run, name, found, self._told(name, events_of_run, kept))
        before = self.replay.runs.get(name) if self.replay is not None else None
        if unchanged and before is not None:
            run.grown_from(before, unchanged, kept)
        return events, run

    def _told(self, name: str, events: pd.DataFrame, kept: int) -> tuple[pd.DataFrame, set[str]]:
        """:func:`case_messages` of the run's :func:`carrying` ``events``, the first ``kept``
        of them as at the last look: read again only when the events carrying a message or a
        battery level are others than then, or among those made again."""
        rows = np.concatenate([self.carried[:kept], carrying(events.iloc[kept:], first=False)])
        rows[:1] = True
        at = np.flatnonzero(rows)
        same = np.array_equal(at, np.flatnonzero(self.carried)) and bool((at < kept).all())
        if self.told is None or not same:
            self.told = case_messages(events[rows], name)
        self.carried = rows
        return self.told


class LiveEvents:
    """A live run's events made as its tags come (what :func:`tags_events` makes of every tag
    heard so far), each time only the tail made again: from the earliest activity still open
    at the last time on, with the starts of the activities that straddle that moment (so
    their ends pair as in the whole run); the events and activity instances before it are
    kept. The whole run is made again when a new tag is older than that moment, or when the
    enrichment and the activity instances would not pair the same starts across it. The
    reader of the pages and the monitor's graph each keep one."""

    def __init__(self) -> None:
        self.tags: list[Tag] = []
        self.heard = Heard()
        self.events: pd.DataFrame | None = None
        #: :func:`activity_instances` of the run's events
        self.found: pd.DataFrame | None = None

    def add(self, name: str, tags: list[Tag]) -> tuple[pd.DataFrame, pd.DataFrame, int, int]:
        """Take the newly heard ``tags`` in: the run's events and activity instances now, how
        many of the first instances and how many of the first events are the last ones'
        (kept as they were, row for row)."""
        self.tags += tags
        self.heard.add(tags)
        fresh = self.heard.nanos[len(self.tags) - len(tags) :]
        # made again whole when the tail will not do
        made = self._made(name, self._tail(fresh)) or self._made(name, None)
        assert made is not None  # the whole run is always made
        self.events, self.found = made[0], made[1]
        return made

    def _made(
        self, name: str, tail: tuple[int, np.ndarray] | None
    ) -> tuple[pd.DataFrame, pd.DataFrame, int, int] | None:
        """The run's events and activity instances made again from the ``tail`` (from when,
        and of which tags) or whole (None), how many of the first instances stay as they
        were and how many of the first events; None when an instance kept and one made again
        start at once (the order of the two is not told without their start events)."""
        cut, chosen = (
            tail if tail is not None else (np.iinfo(np.int64).min, np.arange(len(self.tags)))
        )
        frame, rows = _tag_frame(name, self.tags, self.heard, chosen)
        made = tags_log(frame)
        found = activity_instances(run_events(made, name))
        if tail is None or self.events is None or self.found is None:
            self.heard.pair(frame, rows)
            return made, found, 0, 0
        # the instances over by the cut are kept; the straddling ones are made again
        ended = _nanos(self.found[schema.TIMESTAMP]) < cut
        earlier = self.found[ended & self.found[FINISHED].to_numpy(bool)]
        begun = np.concatenate([_nanos(earlier[START_TIMESTAMP]), _nanos(found[START_TIMESTAMP])])
        if _same_starts(earlier, found):
            return None
        self.heard.pair(frame, rows)
        first = begun[len(earlier) :].min() if len(found) else NEVER
        order = np.argsort(begun, kind="stable")
        found = pd.concat([earlier, found], ignore_index=True).iloc[order]
        # the instances kept that start before any made again lead the run's table as they
        # led it at the last look
        unchanged = int((begun[: len(earlier)] < first).sum())
        kept = int(np.searchsorted(_nanos(self.events[schema.TIMESTAMP]), cut))
        # the straddling starts and their inprogress events before the cut are kept already;
        # the rest numbered as in the whole run, after the events kept
        made = made[_nanos(made[schema.TIMESTAMP]) >= cut].reset_index(drop=True)
        position = pd.Series(np.arange(kept, kept + len(made)), index=made.index)
        made[schema.EVENT_ID] = made[schema.CASE].astype(str) + ":" + position.astype(str)
        events = _joined(self.events.iloc[:kept], made)
        return events, found.reset_index(drop=True), unchanged, kept

    def _tail(self, fresh: np.ndarray) -> tuple[int, np.ndarray] | None:
        """From when (nanoseconds) the run is made again, and the tags (heard positions)
        that make it: every one from then on and the starts of the activities straddling
        then. None when the whole run is made again."""
        if self.events is None or self.found is None or not len(self.events):
            return None
        found, heard = self.found, self.heard
        cut = open_from(found, self.events[schema.TIMESTAMP].iloc[-1]).value
        starting = heard.starting
        never = starting & (heard.ended == NEVER)
        if never.any():  # a start the enrichment left open, its instance ended
            cut = min(cut, int(heard.nanos[never].min()))
        if len(fresh) and fresh.min() < cut:
            return None
        straddling = np.flatnonzero(starting & (heard.nanos < cut) & (heard.ended >= cut))
        starts, ends = _nanos(found[START_TIMESTAMP]), _nanos(found[schema.TIMESTAMP])
        over = found[(starts < cut) & (ends >= cut) & found[FINISHED].to_numpy(bool)]
        begun = self._starts(over)
        if begun is None or not np.array_equal(np.sort(begun), straddling):
            return None  # the two pairings differ across the cut
        return cut, np.union1d(straddling, np.flatnonzero(heard.nanos >= cut))

    def _starts(self, instances: pd.DataFrame) -> np.ndarray | None:
        """The positions of the start tags of ``instances``, or None when they are not
        each told apart by robot, activity and stamp."""
        at = dict.fromkeys(
            zip(
                instances[schema.ROBOT].astype(str),
                instances[schema.ACTIVITY].astype(str),
                _nanos(instances[START_TIMESTAMP]).tolist(),
                strict=True,
            ),
            -1,
        )
        if len(at) < len(instances):
            return None
        for index in np.flatnonzero(np.isin(self.heard.nanos, [key[2] for key in at])):
            tag = self.tags[index]
            key = (tag.robot, tag.activity, int(self.heard.nanos[index]))
            if key in at and tag.lifecycle == schema.START:
                if at[key] != -1:
                    return None  # two starts alike: which one began it is not told
                at[key] = int(index)
        begun = np.array(list(at.values()), dtype=np.int64)
        return None if (begun == -1).any() else begun


def _joined(kept: pd.DataFrame, made: pd.DataFrame) -> pd.DataFrame:
    """The events ``kept`` followed by those ``made`` again, each column of the type the
    whole run's values give it (a column of no message ids yet is of objects, one with some
    of strings)."""
    events = pd.concat([kept, made], ignore_index=True)
    for column in made.columns:
        if column in kept.columns and kept[column].dtype != made[column].dtype:
            events[column] = pd.Series(events[column].tolist(), name=column)
        else:
            events[column] = _one_chunk(events[column])
    return events


def _one_chunk(column: pd.Series) -> pd.Series:
    """``column`` with its values in one piece. A column of strings is held by pyarrow in
    pieces, and concatenating keeps every piece of both sides: the events kept at each look
    would be in one piece more per look, and every slice, mask and take of them cost as many
    pieces (at 20 robots, hundreds after ten minutes: the looks' CPU grew with the run)."""
    values = column.array
    if not isinstance(values, pd.arrays.ArrowExtensionArray):
        return column
    pieces = values.__arrow_array__()
    if pieces.num_chunks <= 1:
        return column
    whole = pd.array(pieces.combine_chunks(), dtype=column.dtype)
    return pd.Series(whole, index=column.index, name=column.name)


def _same_starts(kept: pd.DataFrame, made: pd.DataFrame) -> bool:
    """Whether an instance ``kept`` and one ``made`` again are a robot's at the same moment."""

    def starts(found: pd.DataFrame) -> pd.MultiIndex:
        return pd.MultiIndex.from_arrays(
            [found[schema.ROBOT].astype(str), _nanos(found[START_TIMESTAMP])]
        )

    return bool(starts(made).isin(starts(kept)).any())


def _nanos(times: pd.Series) -> np.ndarray:
    """Nanoseconds since the Unix epoch of ``times`` (UTC)."""
    nanos: np.ndarray = pd.DatetimeIndex(times).asi8
    return nanos


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
    heard = Heard()
    heard.add(tags)
    return tags_log(_tag_frame(name, tags, heard, np.arange(len(tags)))[0])


class Heard:
    """What orders and places the tags of a live run: each one's stamp (nanoseconds) and its
    position among its robot's tags (its source index), in the order they were heard."""

    def __init__(self) -> None:
        self.nanos = np.empty(0, dtype=np.int64)
        self.sources = np.empty(0, dtype=np.int64)
        #: for each start, the stamp of the end the enrichment pairs it with (:data:`NEVER`
        #: while none does); for other tags unread
        self.ended = np.empty(0, dtype=np.int64)
        #: whether each tag starts an activity
        self.starting = np.empty(0, dtype=bool)
        self.counts: dict[str, int] = {}

    def add(self, tags: Sequence[Tag]) -> None:
        sources = []
        for tag in tags:
            sources.append(self.counts.get(tag.robot, 0))
            self.counts[tag.robot] = sources[-1] + 1
        nanos = np.array([tag_nanoseconds(t.stamp) for t in tags], dtype=np.int64)
        self.nanos = np.concatenate([self.nanos, nanos])
        self.sources = np.concatenate([self.sources, np.array(sources, dtype=np.int64)])
        self.ended = np.concatenate([self.ended, np.full(len(tags), NEVER, dtype=np.int64)])
        starting = np.array([tag.lifecycle == schema.START for tag in tags], dtype=bool)
        self.starting = np.concatenate([self.starting, starting])

    def pair(self, frame: pd.DataFrame, rows: np.ndarray) -> None:
        """Note which end closes each start among the tags of ``frame`` (as
        :func:`_tag_frame` made it, ``rows`` their heard positions), as the enrichment
        pairs them."""
        starts, ends, _ = pair_activities(frame)
        self.ended[rows] = NEVER
        self.ended[rows[starts]] = self.nanos[rows[ends]]


def _tag_frame(
    name: str, tags: Sequence[Tag], heard: Heard, chosen: np.ndarray
) -> tuple[pd.DataFrame, np.ndarray]:
    """The ``chosen`` tags as the rows :func:`tags_log` enriches, ordered by stamp and, at
    equal stamps, as heard; and each row's position in heard order."""
    nanos = heard.nanos[chosen]
    robots = [tags[i].robot for i in chosen]
    types = {robot: robot_type(robot) for robot in set(robots)}  # a few robots, many tags
    frame = pd.DataFrame(
        {
            schema.CASE: name,
            schema.TIMESTAMP: pd.to_datetime(nanos, unit="ns", utc=True),
            schema.ACTIVITY: [tags[i].activity for i in chosen],
            schema.LIFECYCLE: [tags[i].lifecycle for i in chosen],
            schema.ROBOT: robots,
            # a live run has no manifest: each robot's type from its name, as prepare's
            schema.ROBOT_TYPE: [types[r] for r in robots],
            schema.MSG_ID: [tags[i].msg_id or None for i in chosen],
            schema.MSG_ROLE: [tags[i].msg_role or None for i in chosen],
            schema.MSG_PAYLOAD: [tags[i].payload or None for i in chosen],
            schema.SOURCE_TOPIC: [tag_topic(r) for r in robots],
            schema.SOURCE_INDEX: heard.sources[chosen],
        }
    )
    order = np.argsort(nanos, kind="stable")
    return frame.iloc[order].reset_index(drop=True), np.asarray(chosen)[order]


def live_replay(driver: Driver, name: str, holding: int | None = None) -> Replay | None:
    """The live run ``name`` as it stands now, or None when no monitor stored one. Only what
    was stored since the last look is read (an index seek by number, whatever the run's
    length): the tags and samples kept are extended; the events are made again when tags
    came, the positions grown when only samples came. Looks wait for each other (one lock):
    of looks asking at once after the store changed, the first makes the run again and the
    others find nothing new.

    With ``holding``, a number of events: the run kept, unread, when it holds that many (a
    page asking the window and the state of the run its summary showed: they answer on that
    run rather than each make it again of the tags stored since, which at 20 robots came
    between any two requests)."""
    with _lock:
        kept = _kept.get(name) or _Kept()
        if holding is not None and kept.replay is not None and len(kept.replay.events) == holding:
            return kept.replay
        new_tags, new_poses = _since(driver, name, kept.tags, kept.positions.poses)
        if new_tags is None or new_poses is None:  # a new run of that name began
            kept = _Kept()
            new_tags, new_poses = live_since(driver, name, 0, 0)
        if not kept.tags and not new_tags:
            _kept.pop(name, None)
            return None
        _kept[name] = kept
        old = kept.replay
        if old is not None and not new_tags and not new_poses:
            return old
        kept.positions.add(new_poses)
        if old is None or new_tags:
            events, run = kept.grow(name, new_tags)
            kept.builds += 1
            kept.replay = LiveReplay(name, events, {}, positions=kept.positions, bare={name: run})
        else:  # the same events: the runs they make are kept, their positions grown
            kept.replay = LiveReplay(name, old.events, {}, positions=kept.positions, bare=old.bare)
        return kept.replay


def live_builds(name: str) -> int:
    """How many times this process made the events of the live run ``name`` (since it last
    began anew), for benchmarks and tests."""
    with _lock:
        kept = _kept.get(name)
        return kept.builds if kept is not None else 0


def _since(
    driver: Driver, name: str, tags: list[Tag], poses: list[Pose]
) -> tuple[list[Tag] | None, list[Pose] | None]:
    """The tags and samples stored after the ``tags`` and ``poses`` held (numbered 1, 2, ...
    as stored), in one round trip; either None when the one held last is no longer stored
    under its number: a new run of that name began. The last one held is read again to
    tell."""
    found = live_since(driver, name, max(len(tags) - 1, 0), max(len(poses) - 1, 0))
    return _after(tags, found[0]), _after(poses, found[1])


def _after(held: list[Any], found: list[Any]) -> list[Any] | None:
    """What ``found`` (read from the last one ``held`` on) adds, or None when it does not
    begin with that one."""
    if not held:
        return found
    if not found or found[0] != held[-1]:
        return None
    return found[1:]
