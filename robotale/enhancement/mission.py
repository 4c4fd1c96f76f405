"""One run as a mission replay: what every robot was doing at any moment, and what happened
between two moments.

Times are seconds since the run's first event, as the Mission page's cursor counts them. At a
moment ``t`` a robot's pose and battery are its last recorded ones at or before ``t`` (a
recording samples them, so nothing is interpolated that was not recorded); its heading is the
direction of its last move; an activity is active from its start up to (not including) its end,
or to the end of the run when the log never ends it; its last message is the latest it sent or
received by ``t``.
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass, field
from functools import cached_property
from typing import Any

import numpy as np
import pandas as pd

from robotale.discovery.instances import FINISHED, START_TIMESTAMP, activity_instances
from robotale.enhancement.mission_state import Facts, Tracks, rows_by_robot
from robotale.enhancement.timeline import NO_ROBOT, case_messages
from robotale.errors import InputError
from robotale.eventlog.schema import (
    ACTIVITY,
    BATTERY,
    CASE,
    LIFECYCLE,
    MSG_ID,
    NONE,
    ROBOT,
    TIMESTAMP,
    X,
    Y,
    Z,
)
from robotale.thresholds import LOW_BATTERY_PERCENT, SLOW_QUANTILE

#: columns that are numbers but no signal to plot: positions in a recording, ids
NOT_SIGNALS = frozenset({"source_index", "event_id", "execution_id", "index"})
#: seconds a slow instance takes at least beyond its kind's median
SLOW_MARGIN = 1.0


@dataclass(frozen=True)
class MissionRun:
    """The run ``case`` of a log, ready to be asked about any moment."""

    case: str
    start: pd.Timestamp
    duration: float
    robots: list[str]
    #: the run's events with ``s`` (seconds since ``start``), in time order
    events: pd.DataFrame
    #: robot, activity, start, end (seconds; end NaN when the log never ends it)
    instances: pd.DataFrame
    #: msg_id, sender, receiver, sent, received (seconds), lost, delayed
    messages: pd.DataFrame
    #: robot, s, x, y, z of every event that carries a position
    positions: pd.DataFrame
    #: numeric columns one can plot
    signals: list[str]
    #: moments worth a look: s, kind, robot, text
    moments: pd.DataFrame
    #: each robot's positions as kept while they grew (a live run's); None: read from
    #: :attr:`positions` when first asked
    tracks: Tracks | None = field(default=None, compare=False, repr=False)

    #: the tables of a run, by name (what :meth:`parts` and :meth:`from_parts` carry)
    TABLES = ("events", "instances", "messages", "positions", "moments")

    def parts(self) -> tuple[dict[str, Any], dict[str, pd.DataFrame]]:
        """The run as plain values (JSON) and tables, to be kept and read back whole by
        :meth:`from_parts`."""
        values = {
            "case": self.case,
            "start": self.start.isoformat(),
            "duration": self.duration,
            "robots": self.robots,
            "signals": self.signals,
        }
        return values, {name: getattr(self, name) for name in self.TABLES}

    @classmethod
    def from_parts(cls, values: dict[str, Any], tables: dict[str, pd.DataFrame]) -> MissionRun:
        """The run :meth:`parts` gave ``values`` and ``tables`` of."""
        return cls(
            case=str(values["case"]),
            start=pd.Timestamp(values["start"]),
            duration=float(values["duration"]),
            robots=[str(robot) for robot in values["robots"]],
            signals=[str(signal) for signal in values["signals"]],
            **{name: tables[name] for name in cls.TABLES},
        )

    # -- one moment ------------------------------------------------------------------------

    def state(self, t: float) -> dict[str, Any]:
        """Every robot at ``t`` seconds: pose, heading, battery, active activities and its
        last message."""
        return {
            "case": self.case,
            "t": t,
            "time": _iso(self.start + pd.Timedelta(seconds=t)),
            "duration": self.duration,
            "robots": {robot: self._robot_state(robot, t) for robot in self.robots},
        }

    def _robot_state(self, robot: str, t: float) -> dict[str, Any]:
        track = self.position_tracks.get(robot)
        return {
            "pose": track.pose(t),
            "heading": track.heading(t),
            "battery": self.facts.battery_at(robot, t),
            "activities": self.facts.active(robot, t),
            "last_message": self.facts.last_message(robot, t),
        }

    @cached_property
    def position_tracks(self) -> Tracks:
        """Each robot's positions in time arrays: the ones kept as they grew (a live run's),
        else read once from :attr:`positions`."""
        return self.tracks if self.tracks is not None else Tracks.of(self.positions)

    @cached_property
    def facts(self) -> Facts:
        """Each robot's battery, activities and messages in time arrays, read once."""
        return Facts.of(self.events, self.instances, self.messages)

    def active(self, robot: str, t: float) -> list[str]:
        """The activities of ``robot`` running at ``t``, in start order."""
        return self.facts.active(robot, t)

    def active_instances(self, t: float) -> pd.DataFrame:
        end = self.instances["end"].fillna(math.inf)
        return self.instances[(self.instances["start"] <= t) & (t < end)]

    # -- between two moments ---------------------------------------------------------------

    def window(self, start: float, end: float) -> dict[str, Any]:
        """The events, messages, positions and moments between ``start`` and ``end`` s."""
        if end < start:
            raise InputError(f"the window ends ({end} s) before it starts ({start} s).")
        # the events are in time order: the window's are found by bisection, not by a pass
        # over the whole run (a live run's grows at every look)
        seconds = self.events["s"].to_numpy(float)
        first = int(np.searchsorted(seconds, start, side="left"))
        last = int(np.searchsorted(seconds, end, side="right"))
        events = self.events.iloc[first:last]
        control = events[events[LIFECYCLE].astype("string").fillna("") != NONE]
        messages = self.messages
        sent_in = messages["sent"].between(start, end)
        received_in = messages["received"].between(start, end)
        moments = self.moments[self.moments["s"].between(start, end)]
        return {
            "case": self.case,
            "from": start,
            "to": end,
            "events": [
                {
                    "s": float(row.s),
                    "robot": str(row.robot),
                    "activity": str(row.activity),
                    "lifecycle": None if pd.isna(row.lifecycle) else str(row.lifecycle),
                    "msg_id": None if pd.isna(row.msg_id) else str(row.msg_id),
                }
                for row in _event_rows(control)
            ],
            "messages": _records(messages[sent_in | received_in]),
            "positions": self._positions_between(start, end),
            "moments": _records(moments),
        }

    def _positions_between(self, start: float, end: float) -> dict[str, list[list[float]]]:
        """``{robot: [[s, x, y, z], ...]}`` from ``start`` to ``end`` seconds, in time order:
        a live run's read from its robots' tracks by bisection, so the window costs what it
        holds, not the whole run's samples."""
        if self.tracks is not None:
            return self.tracks.between(start, end)
        seconds = self.positions["s"].to_numpy(float)
        positions = self.positions[(seconds >= start) & (seconds <= end)]
        xyzs = positions[["s", "x", "y", "z"]].to_numpy(float)
        return {
            robot: xyzs[rows].tolist()
            for robot, rows in sorted(rows_by_robot(positions["robot"]).items())
        }

    def series(self, column: str) -> dict[str, list[list[float]]]:
        """``{robot: [[s, value], ...]}`` of a numeric column, for a plot."""
        if column not in self.signals:
            known = ", ".join(self.signals) or "none"
            raise InputError(f"the run has no numeric field {column!r}; it has {known}.")
        values = pd.to_numeric(self.events[column], errors="coerce")
        table = pd.DataFrame({"robot": self.events[ROBOT], "s": self.events["s"], "v": values})
        table = table.dropna(subset=["v"])
        return {
            str(robot): rows[["s", "v"]].to_numpy(float).tolist()
            for robot, rows in table.groupby("robot", sort=True)
        }

    def summary(self, since: float | None = None) -> dict[str, Any]:
        """What the page needs before it asks about a moment; from ``since`` seconds on only
        (a page following a live run holds the rest): the event times from then, the
        instances running or begun from then (those over before it are as they were), and
        all the moments (few, and a slow one is judged against every instance so far)."""
        if since is None:
            return {**self.head(), **self._made_of_events}
        return {
            **self.head(),
            "since": since,
            # a page holding other than these many earlier times missed a late tag: it asks
            # for the whole summary again
            "times_before": self._times_before(since),
            "event_times": self._event_times(since),
            # the records of the instances kept from the last look are not made again
            "instances": [
                self.instance_records[i]
                for i in np.flatnonzero(_changed_since(self.instances, since).to_numpy(bool))
            ],
            "moments": self.moment_records,
        }

    def _times_before(self, since: float) -> int:
        """How many distinct :meth:`summary` event times are before ``since``."""
        times = self._control_times
        return int(np.unique(times[: np.searchsorted(times, since, side="left")]).size)

    @cached_property
    def _control_times(self) -> np.ndarray:
        """The times (to the microsecond) of the control events, sorted."""
        return _control_times_of(self.events)

    def _event_times(self, since: float) -> list[float]:
        """The distinct times (to the microsecond) of the control events at or after
        ``since``, sorted: only the events from shortly before it are read."""
        first = int(np.searchsorted(self.events["s"].to_numpy(float), since - 1e-6))
        return [s for s in _event_times(self.events.iloc[first:]) if s >= since]

    def head(self) -> dict[str, Any]:
        """The little the page draws a first moment with: the run's start, length, number
        of events (a live run grown), robots, fields and whether it has positions."""
        return {
            "case": self.case,
            "start": _iso(self.start),
            "duration": self.duration,
            "events": len(self.events),
            "robots": self.robots,
            "signals": self.signals,
            "has_positions": not self.positions.empty,
        }

    @cached_property
    def _made_of_events(self) -> dict[str, Any]:
        return {
            "event_times": _event_times(self.events),
            "instances": self.instance_records,
            "moments": self.moment_records,
        }

    @cached_property
    def moment_records(self) -> list[dict[str, Any]]:
        """:attr:`moments` as JSON records (all of them in every summary: they are few)."""
        return _records(self.moments)

    @cached_property
    def instance_records(self) -> list[dict[str, Any]]:
        """:attr:`instances` as JSON records, row by row."""
        return _records(self.instances)

    def grown_from(self, earlier: MissionRun, kept: int, events: int = 0) -> None:
        """Take over what ``earlier``, this run before events came after its first ``kept``
        activity instances and its first ``events`` events, read of those (they are the same
        rows at the same seconds), so only the later ones are read again."""
        if earlier.start != self.start:
            return
        # cached_property keeps its values in the instance's dict
        records = earlier.__dict__.get("instance_records")
        if records is not None and len(records) >= kept:
            self.__dict__["instance_records"] = records[:kept] + _records(
                self.instances.iloc[kept:]
            )
        times = earlier.__dict__.get("_control_times")
        if times is not None and 0 < events <= len(earlier.events):
            # the events are in time order and a time's rounding keeps that order, so the
            # control times of the first events lead the sorted times, as many as there are
            # control events among them: those of the later events, few, are counted
            first = len(times) - _control_count(earlier.events.iloc[events:])
            later = _control_times_of(self.events.iloc[events:])
            self.__dict__["_control_times"] = np.concatenate([times[:first], later])

    def with_positions(self, positions: pd.DataFrame, tracks: Tracks) -> MissionRun:
        """The same run with other positions (``tracks`` holding them per robot): what is
        read of its events once is kept, not read again."""
        moved = dataclasses.replace(self, positions=positions, tracks=tracks)
        # cached_property keeps its values in the instance's dict: the ones that do not
        # depend on the positions are handed on
        for name in ("facts", "_made_of_events", "instance_records", "_control_times"):
            if name in self.__dict__:
                moved.__dict__[name] = self.__dict__[name]
        return moved


def mission_run(log: pd.DataFrame, case: str, slow: pd.DataFrame | None = None) -> MissionRun:
    """The run ``case`` of ``log`` (an :class:`InputError` naming some runs when it has none);
    ``slow`` is :func:`slow_limits` of ``log`` when it was kept, else it is computed here."""
    # also checks the run exists; a robot with a bar on the timeline has an instance here
    run_messages, lanes = case_messages(log, case)
    events = run_events(log, case)
    found = activity_instances(events)
    if slow is None:
        # a log of this run alone, in time order (a live run's): its instances are the log's
        alone = len(events) == len(log) and events.index.equals(log.index)
        slow = _slow_limits_of(found) if alone else slow_limits(log)
    return _assembled(str(case), events, found, run_messages, lanes, slow)


def run_events(log: pd.DataFrame, case: str) -> pd.DataFrame:
    """The events of run ``case`` of ``log`` in time order, each with its robot's name."""
    chosen = log[CASE].astype("string").eq(str(case)).fillna(False).to_numpy(bool)
    # a live run's log is its one run, in time order but for a late tag: it is asked at every
    # look, so neither a copy of every row nor a sort is made when none is needed
    events = log if chosen.all() else log[chosen]
    if not events[TIMESTAMP].is_monotonic_increasing:
        events = events.sort_values(TIMESTAMP, kind="stable")
    robots_column = (
        events[ROBOT].astype("string").fillna(NO_ROBOT)
        if ROBOT in events.columns
        else pd.Series(NO_ROBOT, index=events.index)
    )
    return events.assign(**{ROBOT: robots_column.astype(str)})


def lone_run(
    events: pd.DataFrame,
    case: str,
    found: pd.DataFrame,
    told: tuple[pd.DataFrame, set[str]] | None = None,
) -> MissionRun:
    """The run ``case`` of a log holding only it (a live run's), its :func:`run_events` being
    ``events`` and their :func:`activity_instances` ``found``: what :func:`mission_run`
    makes of that log, without pairing the activities again. ``told``: the
    :func:`case_messages` of its :func:`carrying` events, when the caller kept them."""
    if told is None:
        told = case_messages(events[carrying(events)], case)
    run_messages, lanes = told
    return _assembled(str(case), events, found, run_messages, lanes, _slow_limits_of(found))


def carrying(events: pd.DataFrame, *, first: bool = True) -> np.ndarray:
    """Which ``events`` the messages and lanes of a lone run are read of: those that carry
    a message or a battery level (a message's delay is judged among all of them), and the
    first, which names the run (unless ``first`` is False: ``events`` are a later part)."""
    found = events[MSG_ID].notna() if MSG_ID in events.columns else events[ROBOT].isna()
    if BATTERY in events.columns:
        found |= pd.to_numeric(events[BATTERY], errors="coerce").notna()
    rows: np.ndarray = found.to_numpy(bool).copy()
    rows[:1] |= first
    return rows


def open_from(found: pd.DataFrame, last: pd.Timestamp) -> pd.Timestamp:
    """The start of the earliest activity instance still open among ``found`` (of a run whose
    events end at ``last``), else ``last``: a later event can change no instance that started
    earlier, since all of those ended."""
    still_open = ~found[FINISHED].astype(bool)
    return min(found[START_TIMESTAMP][still_open].min(), last) if still_open.any() else last


def _assembled(
    case: str,
    events: pd.DataFrame,
    found: pd.DataFrame,
    run_messages: pd.DataFrame,
    lanes: set[str],
    slow: pd.DataFrame,
) -> MissionRun:
    """The run of its :func:`run_events`, their instances ``found``, its messages and lanes
    as :func:`case_messages` reads them, and the ``slow`` limits."""
    start = events[TIMESTAMP].iloc[0]
    events = events.assign(s=_seconds(events[TIMESTAMP], start))
    instances = _instances(found, start)
    messages = _messages(run_messages, start)
    positions = _positions(events)
    # a robot whose only activity is still running (a live run's) has no bar yet, but a lane;
    # the names told apart by unique() (a set of a column iterates its every row, a live
    # run's look would pay for the whole run)
    robots = sorted(lanes | set(positions["robot"].unique()) | set(instances["robot"].unique()))
    return MissionRun(
        case=case,
        start=start,
        duration=float(events["s"].iloc[-1]),
        robots=robots,
        events=events.reset_index(drop=True),
        instances=instances,
        messages=messages,
        positions=positions,
        signals=_signals(events),
        moments=_moments(slow, events, instances, messages, start),
    )


def _seconds(times: pd.Series, start: pd.Timestamp) -> pd.Series:
    return (times - start).dt.total_seconds()


def _instances(found: pd.DataFrame, start: pd.Timestamp) -> pd.DataFrame:
    """The run's activity instances (``found`` by :func:`activity_instances`) in seconds."""
    if found.empty:
        return pd.DataFrame(columns=["robot", "activity", "start", "end"])
    ends = _seconds(found[TIMESTAMP], start).where(found[FINISHED].astype(bool))
    table = pd.DataFrame(
        {
            "robot": found[ROBOT].astype(str),
            "activity": found[ACTIVITY].astype(str),
            "start": _seconds(found[START_TIMESTAMP], start),
            "end": ends,
        }
    )
    return table.sort_values(["start", "robot"], kind="stable").reset_index(drop=True)


def _messages(messages: pd.DataFrame, start: pd.Timestamp) -> pd.DataFrame:
    columns = ["msg_id", "sender", "receiver", "sent", "received", "lost", "delayed"]
    if messages.empty:
        return pd.DataFrame(columns=columns)
    table = messages[columns].copy()
    for column in ("sent", "received"):
        table[column] = _seconds(pd.to_datetime(table[column], utc=True), start)
    return table.reset_index(drop=True)


def _positions(events: pd.DataFrame) -> pd.DataFrame:
    if X not in events.columns or Y not in events.columns:
        return pd.DataFrame(columns=["robot", "s", "x", "y", "z"])
    x = pd.to_numeric(events[X], errors="coerce")
    y = pd.to_numeric(events[Y], errors="coerce")
    z = pd.to_numeric(events[Z], errors="coerce") if Z in events.columns else 0.0
    table = pd.DataFrame({"robot": events[ROBOT], "s": events["s"], "x": x, "y": y, "z": z})
    return table.dropna(subset=["x", "y"]).reset_index(drop=True)


def _signals(events: pd.DataFrame) -> list[str]:
    """The log's numeric columns (battery, positions, any perspective or topic field)."""
    found = []
    for column in events.columns:
        if column in NOT_SIGNALS or column == "s" or column.startswith("_"):
            continue
        values = events[column]
        if pd.api.types.is_bool_dtype(values):
            continue
        if pd.api.types.is_numeric_dtype(values) and values.notna().any():
            found.append(str(column))
    return found


def _moments(
    slow: pd.DataFrame,
    events: pd.DataFrame,
    instances: pd.DataFrame,
    messages: pd.DataFrame,
    start: pd.Timestamp,
) -> pd.DataFrame:
    """The run's moments worth a look: a lost or delayed message (where it was sent), a
    robot's battery first falling below :data:`~robotale.thresholds.LOW_BATTERY_PERCENT`
    percent, an activity instance slower than :data:`~robotale.thresholds.SLOW_QUANTILE` of
    its kind in the whole log (where it started)."""
    rows: list[dict[str, Any]] = []
    for row in messages.itertuples(index=False):
        if row.lost or row.delayed:
            what = "lost" if row.lost else "delayed"
            text = f"message {row.msg_id} from {row.sender} {what}"
            rows.append(
                {"s": row.sent, "kind": f"{what} message", "robot": row.sender, "text": text}
            )
    if BATTERY in events.columns:
        levels = pd.to_numeric(events[BATTERY], errors="coerce")
        low = events[levels < LOW_BATTERY_PERCENT]
        for robot, first in low.groupby(ROBOT, sort=True)["s"].min().items():
            text = f"{robot}'s battery below {LOW_BATTERY_PERCENT:g}%"
            rows.append({"s": first, "kind": "low battery", "robot": robot, "text": text})
    rows += _slow(slow, instances)
    table = pd.DataFrame(rows, columns=["s", "kind", "robot", "text"])
    return table.sort_values("s", kind="stable").reset_index(drop=True)


#: the columns of :func:`slow_limits`
SLOW_COLUMNS = ["robot", "activity", "limit", "median", "count"]


def slow_limits(log: pd.DataFrame) -> pd.DataFrame:
    """What counts as slow for each robot and activity of the whole ``log``: the
    :data:`SLOW_QUANTILE` (``limit``), the ``median`` and the ``count`` of the seconds its
    finished instances took. The same for every run of the log, so it can be kept."""
    return _slow_limits_of(activity_instances(log))


def _slow_limits_of(every: pd.DataFrame) -> pd.DataFrame:
    """:func:`slow_limits` of a log whose activity instances are ``every``."""
    every = every[every[FINISHED].astype(bool)]
    if every.empty or ROBOT not in every.columns:
        return pd.DataFrame(columns=SLOW_COLUMNS)
    seconds = (every[TIMESTAMP] - every[START_TIMESTAMP]).dt.total_seconds()
    keys = [
        every[ROBOT].astype(str).rename("robot"),
        every[ACTIVITY].astype(str).rename("activity"),
    ]
    groups = seconds.groupby(keys)
    table = pd.DataFrame(
        {
            "limit": groups.quantile(SLOW_QUANTILE),
            "median": groups.median(),
            "count": groups.size(),
        }
    )
    return table.reset_index()[SLOW_COLUMNS]


def _slow(slow: pd.DataFrame, instances: pd.DataFrame) -> list[dict[str, Any]]:
    """The run's instances slower than ``slow`` (:func:`slow_limits`) says of their kind, in
    the order of ``instances``: judged in arrays, as a live run's every instance is again at
    each look."""
    done = instances.dropna(subset=["end"])
    if done.empty or slow.empty:
        return []
    kinds = pd.MultiIndex.from_arrays([slow["robot"].astype(str), slow["activity"].astype(str)])
    robots, activities = done["robot"].astype(str), done["activity"].astype(str)
    at = kinds.get_indexer(pd.MultiIndex.from_arrays([robots, activities]))
    known = at >= 0
    limit = np.where(known, slow["limit"].to_numpy(float)[at], np.nan)
    median = np.where(known, slow["median"].to_numpy(float)[at], np.nan)
    count = np.where(known, slow["count"].to_numpy(np.int64)[at], 0)
    starts = done["start"].to_numpy(float)
    took = done["end"].to_numpy(float) - starts
    # too few to say what is slow under 3; a second past the typical one, not a rounding of
    # an instant one
    with np.errstate(invalid="ignore"):
        slower = (count >= 3) & (took > limit + 1e-9) & (took - median >= SLOW_MARGIN)
    return [
        {
            "s": float(starts[i]),
            "kind": "slow activity",
            "robot": robots.iloc[i],
            "text": f"{activities.iloc[i]} by {robots.iloc[i]} took {took[i]:.1f} s",
        }
        for i in np.flatnonzero(slower)
    ]


def _is_control(events: pd.DataFrame) -> np.ndarray:
    """Which ``events`` are no message or reading alone (a step of the page's cursor)."""
    control: np.ndarray = events[LIFECYCLE].astype("string").fillna("").to_numpy() != NONE
    return control


def _control_count(events: pd.DataFrame) -> int:
    return int(_is_control(events).sum())


def _control_times_of(events: pd.DataFrame) -> np.ndarray:
    """The times (to the microsecond) of the control ``events``, sorted."""
    times: np.ndarray = np.sort(events["s"].to_numpy(float)[_is_control(events)].round(6))
    return times


def _event_times(events: pd.DataFrame) -> list[float]:
    """The distinct times (seconds, to the microsecond) of ``events`` that are no message
    or reading alone (a step of the page's cursor), sorted."""
    control = events[events[LIFECYCLE].astype("string").fillna("") != NONE]
    return sorted(set(control["s"].round(6).tolist()))


def _changed_since(instances: pd.DataFrame, since: float) -> pd.Series:
    """Which of ``instances`` may differ from what a look at ``since`` seconds saw: those
    begun from then on, still running, or ended from then on."""
    end = instances["end"].astype(float)
    return (instances["start"].astype(float) >= since) | end.isna() | (end >= since)


def _event_rows(events: pd.DataFrame):
    msg = events[MSG_ID] if MSG_ID in events.columns else pd.Series(None, index=events.index)
    table = pd.DataFrame(
        {
            "s": events["s"],
            "robot": events[ROBOT],
            "activity": events[ACTIVITY],
            "lifecycle": events[LIFECYCLE] if LIFECYCLE in events.columns else None,
            "msg_id": msg,
        }
    )
    return table.itertuples(index=False)


def _records(table: pd.DataFrame) -> list[dict[str, Any]]:
    return [{k: _plain(v) for k, v in row.items()} for row in table.to_dict(orient="records")]


def _plain(value: Any) -> Any:
    if isinstance(value, (np.bool_, bool)):
        return bool(value)
    if isinstance(value, (np.integer, np.floating, float, int)):
        return _number(value)
    if value is None or (not isinstance(value, str) and pd.isna(value)):
        return None
    return str(value)


def _number(value: Any) -> float | None:
    number = float(value)
    return number if math.isfinite(number) else None


def _iso(moment: pd.Timestamp) -> str:
    return moment.isoformat()
