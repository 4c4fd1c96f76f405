"""Every robot of a run at a moment, answered from per-robot time arrays.

A run's tables are read once into sorted arrays per robot (times, positions, battery levels,
activity instances, messages); a moment is then found by bisection, so asking about one costs
O(robots · log n) instead of filtering the tables again. The answers are those the rules of
:mod:`robotale.enhancement.mission` state: a robot's pose and battery are its last recorded
ones at or before ``t``, its heading the direction of its last move, an activity is active
from its start up to (not including) its end, its last message the latest it sent or received.

The positions can grow: :meth:`Tracks.extended` appends samples later than a robot's last one
in place (a live run's odometry), so a growing run is not read again whole.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any

import numpy as np
import pandas as pd

from robotale.eventlog.schema import BATTERY, ROBOT

#: a move shorter than this (metres) gives no heading: a standing robot's noise
MIN_MOVE = 1e-3


def _last_at(times: np.ndarray, t: float) -> int:
    """The index of the last of the sorted ``times`` at or before ``t`` (-1: none)."""
    return int(np.searchsorted(times, t, side="right")) - 1


@dataclass
class Track:
    """One robot's positions in time order, in arrays that grow by doubling."""

    size: int = 0
    s: np.ndarray = field(default_factory=lambda: np.empty(0))
    xyz: np.ndarray = field(default_factory=lambda: np.empty((0, 3)))
    #: for each sample, the index of the last sample (up to it) that moved from the one
    #: before by more than :data:`MIN_MOVE`, -1 when none did
    moved: np.ndarray = field(default_factory=lambda: np.empty(0, dtype=np.int64))

    def append(self, s: np.ndarray, xyz: np.ndarray) -> None:
        """Add samples at times ``s`` (sorted, none before the last one held)."""
        count = len(s)
        if self.size + count > len(self.s):
            room = max(2 * len(self.s), self.size + count, 64)
            self.s = np.resize(self.s, room)
            self.xyz = np.resize(self.xyz, (room, 3))
            self.moved = np.resize(self.moved, room)
        at = slice(self.size, self.size + count)
        self.s[at], self.xyz[at] = s, xyz
        # each new sample's step from the one before it (the last one held, for the first)
        first = max(self.size - 1, 0)
        steps = np.diff(self.xyz[first : self.size + count, :2], axis=0)
        index = np.arange(first + 1, self.size + count)
        moves = np.where(np.hypot(steps[:, 0], steps[:, 1]) > MIN_MOVE, index, -1)
        before = self.moved[self.size - 1] if self.size else -1
        if not self.size:
            self.moved[0] = -1  # a track's first sample made no move
        self.moved[first + 1 : self.size + count] = np.maximum.accumulate(
            np.concatenate([[before], moves])
        )[1:]
        self.size += count

    def pose(self, t: float) -> dict[str, float | None] | None:
        last = _last_at(self.s[: self.size], t)
        if last < 0:
            return None
        return {axis: _number(v) for axis, v in zip(("x", "y", "z"), self.xyz[last], strict=True)}

    def heading(self, t: float) -> float | None:
        """Radians, counter-clockwise from +x, of the last move at or before ``t``."""
        last = _last_at(self.s[: self.size], t)
        if last < 1:
            return None
        step = int(self.moved[last])
        if step < 1:
            return None
        dx, dy = self.xyz[step, :2] - self.xyz[step - 1, :2]
        return float(math.atan2(dy, dx))


class Tracks:
    """Every robot's :class:`Track`, from a positions table (robot, s, x, y, z)."""

    def __init__(self) -> None:
        self.robots: dict[str, Track] = {}

    @classmethod
    def of(cls, positions: pd.DataFrame) -> Tracks:
        tracks = cls()
        tracks.extended(positions)
        return tracks

    def extended(self, positions: pd.DataFrame) -> bool:
        """Add ``positions`` (in time order per robot); False, and nothing added, when one
        is earlier than its robot's last sample held (read the whole table again then)."""
        positions = positions.dropna(subset=["s"])  # a sample of no time is never at one
        if positions.empty:
            return True
        groups = rows_by_robot(positions["robot"])
        s = positions["s"].to_numpy(float)
        for robot, rows in groups.items():
            track = self.robots.get(robot)
            if track is not None and track.size and s[rows].min() < track.s[track.size - 1]:
                return False
        xyz = positions[["x", "y", "z"]].to_numpy(float)
        for robot, rows in groups.items():
            self.robots.setdefault(robot, Track()).append(s[rows], xyz[rows])
        return True

    def between(self, start: float, end: float) -> dict[str, list[list[float]]]:
        """``{robot: [[s, x, y, z], ...]}`` of the samples from ``start`` to ``end`` seconds
        (both included), robots in name order, those with none left out."""
        found = {}
        for robot in sorted(self.robots):
            track = self.robots[robot]
            times = track.s[: track.size]
            first = int(np.searchsorted(times, start, side="left"))
            last = int(np.searchsorted(times, end, side="right"))
            if first < last:
                rows = np.column_stack([times[first:last], track.xyz[first:last]])
                found[robot] = rows.tolist()
        return found

    def get(self, robot: str) -> Track:
        return self.robots.get(robot) or Track()


@dataclass(frozen=True)
class Facts:
    """What a run's events, instances and messages say of each robot, in sorted arrays."""

    #: robot -> (times, levels) of its battery readings
    battery: dict[str, tuple[np.ndarray, np.ndarray]]
    #: robot -> (starts, ends with inf for never, activities) in start order
    activities: dict[str, tuple[np.ndarray, np.ndarray, list[str]]]
    #: robot -> (times, rows) of the messages it sent or received, the one that counts
    #: last among those of one time (see :func:`_message_entries`)
    messages: dict[str, tuple[np.ndarray, list[dict[str, Any]]]]

    @classmethod
    def of(cls, events: pd.DataFrame, instances: pd.DataFrame, messages: pd.DataFrame) -> Facts:
        return cls(_battery(events), _activities(instances), _message_entries(messages))

    def battery_at(self, robot: str, t: float) -> float | None:
        times, levels = self.battery.get(robot, (np.empty(0), np.empty(0)))
        last = _last_at(times, t)
        return _number(levels[last]) if last >= 0 else None

    def active(self, robot: str, t: float) -> list[str]:
        """The activities of ``robot`` running at ``t``, in start order."""
        found = self.activities.get(robot)
        if found is None:
            return []
        starts, ends, names = found
        running = np.flatnonzero((starts <= t) & (t < ends))
        return [names[i] for i in running]

    def last_message(self, robot: str, t: float) -> dict[str, Any] | None:
        times, rows = self.messages.get(robot, (np.empty(0), []))
        last = _last_at(times, t)
        return dict(rows[last]) if last >= 0 else None


def _battery(events: pd.DataFrame) -> dict[str, tuple[np.ndarray, np.ndarray]]:
    if BATTERY not in events.columns:
        return {}
    table = pd.DataFrame(
        {
            "robot": events[ROBOT],
            "s": events["s"],
            "v": pd.to_numeric(events[BATTERY], errors="coerce"),
        }
    ).dropna(subset=["s", "v"])
    return {
        str(robot): (rows["s"].to_numpy(float), rows["v"].to_numpy(float))
        for robot, rows in table.groupby("robot", sort=False)
    }


def _activities(
    instances: pd.DataFrame,
) -> dict[str, tuple[np.ndarray, np.ndarray, list[str]]]:
    table = instances.dropna(subset=["start"])
    names = table["activity"].astype(str).to_numpy()
    # each column read once, then cut per robot (not read again for every robot)
    starts = table["start"].to_numpy(float)
    ends = table["end"].astype(float).fillna(math.inf).to_numpy(float)
    return {
        robot: (starts[rows], ends[rows], names[rows].tolist())
        for robot, rows in rows_by_robot(table["robot"]).items()
    }


def rows_by_robot(robots: pd.Series) -> dict[str, np.ndarray]:
    """The positions of each robot's rows, in their order: what a group-by gives, in arrays
    (a live run's tables are grouped again at every look)."""
    codes, names = pd.factorize(robots, sort=False)
    order = np.argsort(codes, kind="stable")
    bounds = np.searchsorted(codes[order], np.arange(len(names) + 1))
    return {
        str(name): order[bounds[i] : bounds[i + 1]]
        for i, name in enumerate(names)
        if bounds[i] < bounds[i + 1]
    }


def _message_entries(
    messages: pd.DataFrame,
) -> dict[str, tuple[np.ndarray, list[dict[str, Any]]]]:
    """Each robot's messages as it sent or received them, sorted so that the last one at or
    before a moment is the one that counts: the latest; of one time, a sent one before a
    received one, and of those the first in the table."""
    entries: list[tuple[str, float, int, int, dict[str, Any]]] = []
    for position, row in enumerate(messages.itertuples(index=False)):
        for role, robot, at, other in (
            ("sent", row.sender, row.sent, row.receiver),
            ("received", row.receiver, row.received, row.sender),
        ):
            if pd.isna(robot) or pd.isna(at):
                continue
            answer = {
                "msg_id": str(row.msg_id),
                "role": role,
                "with": None if pd.isna(other) else str(other),
                "s": float(at),
                "lost": bool(row.lost),
            }
            # ties: sent outranks received, an earlier row a later one; the best sorts last
            entries.append((str(robot), float(at), int(role == "sent"), -position, answer))
    entries.sort(key=lambda e: e[:4])
    found: dict[str, tuple[list[float], list[dict[str, Any]]]] = {}
    for robot, at, _, _, answer in entries:
        times, rows = found.setdefault(robot, ([], []))
        times.append(at)
        rows.append(answer)
    return {robot: (np.array(times, dtype=float), rows) for robot, (times, rows) in found.items()}


def _number(value: Any) -> float | None:
    number = float(value)
    return number if math.isfinite(number) else None
