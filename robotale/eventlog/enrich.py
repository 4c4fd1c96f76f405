"""TALE enrichment: tag events plus continuous robot data -> a multi-perspective event log.

Tags say what a robot did (an activity's start and completion, a message sent or received);
the other topics (odometry, battery ...) say where it was and how it was doing. Following the
thesis (6.2.1, processing), every tag event takes the perspective values of the closest sample at
or after its time from the same robot in the same run, and between the start and the completion
of an activity ``inprogress`` events carry those values at a chosen rate.

Both are sorted joins (:func:`pandas.merge_asof`), never a search per event, so a run with a
million samples is enriched in about a second.
"""

from __future__ import annotations

import warnings
from collections import defaultdict, deque
from collections.abc import Mapping
from dataclasses import dataclass
from fnmatch import fnmatchcase

import numpy as np
import pandas as pd

from robotale.errors import InputError
from robotale.eventlog import schema

CASE, TIME, ROBOT, ACTIVITY = schema.CASE, schema.TIMESTAMP, schema.ROBOT, schema.ACTIVITY
LIFECYCLE, STATE = schema.LIFECYCLE, schema.STATE
KEYS = [CASE, ROBOT]
#: the order of events that share a timestamp: tags as recorded, then inprogress rows.
_ORDER = "_order"
#: lifecycles that end an activity: its completion, or an outcome such as an aborted goal
_CLOSING = schema.ENDINGS


class PreparationWarning(UserWarning):
    """Something odd in the recording that does not stop the preparation."""


@dataclass(frozen=True)
class Perspective:
    """Continuous data taken from one kind of topic: ``columns`` maps a log column to a field.

    ``topic`` is a glob over topic names (``/*/odom``), or several separated by ``|``; the robot
    a sample belongs to is the topic's namespace. ``scale`` multiplies a column (the battery's
    0-1 fraction -> percent).
    """

    name: str
    topic: str
    columns: Mapping[str, str]
    scale: Mapping[str, float] | None = None

    def matches(self, topic: str) -> bool:
        return any(fnmatchcase(topic, glob) for glob in self.topic.split("|"))


ODOM = Perspective(
    "odom",
    "/*/odom|/odom",
    {"x": "pose.pose.position.x", "y": "pose.pose.position.y", "z": "pose.pose.position.z"},
)
BATTERY = Perspective(
    "battery", "/*/battery|/battery", {"battery": "percentage"}, {"battery": 100.0}
)
BUILTIN: dict[str, Perspective] = {p.name: p for p in (ODOM, BATTERY)}


def parse_perspective(spec: str) -> Perspective:
    """A perspective from its command-line form.

    ``odom`` or ``battery`` (built in), ``odom=/*/odometry/filtered`` (a built-in on other
    topics), or ``NAME=TOPIC_GLOB:FIELD`` for any other field, e.g. ``range=/*/range:range``
    (the column is NAME).
    """
    name, _, rest = spec.strip().partition("=")
    if not rest:
        if name not in BUILTIN:
            raise InputError(
                f"Unknown perspective {name!r}: use {', '.join(BUILTIN)} or NAME=TOPIC:FIELD."
            )
        return BUILTIN[name]
    topic, _, path = rest.partition(":")
    if not path:
        if name not in BUILTIN:
            raise InputError(
                f"Perspective {spec!r} names no field: write it as {name}={topic}:FIELD."
            )
        return Perspective(name, topic, BUILTIN[name].columns, BUILTIN[name].scale)
    if not name.isidentifier() or not topic.startswith("/"):
        raise InputError(f"Perspective {spec!r} is not NAME=/TOPIC_GLOB:FIELD.")
    return Perspective(name, topic, {name: path})


def enrich(
    tags: pd.DataFrame,
    samples: Mapping[str, pd.DataFrame],
    *,
    rate: float = 1.0,
) -> pd.DataFrame:
    """The multi-perspective event log of tagged events.

    ``tags`` has the canonical columns (case, time, activity, lifecycle, robot, and any message
    columns), one row per tag in recording order. ``samples`` maps a perspective's name to its
    samples: case, robot, time and value columns. ``rate`` is how many ``inprogress`` events per
    second of an activity (0 for none). The result is ordered by case, then time.
    """
    if rate < 0:
        raise InputError(f"The inprogress rate must be 0 or more per second, not {rate}.")
    events = _ordered(tags.assign(**{STATE: schema.NONE}))
    starts, completes, orphans = pair_activities(events)
    if len(orphans):
        warnings.warn(_orphan_message(events.iloc[orphans]), PreparationWarning, stacklevel=2)
    progress = inprogress(events, starts, completes, rate)
    events = _ordered(pd.concat([events, progress], ignore_index=True))
    for frame in samples.values():
        events = upper_closest(events, frame)
    return events.drop(columns=_ORDER)


def _ordered(events: pd.DataFrame) -> pd.DataFrame:
    if _ORDER not in events:
        events = events.assign(**{_ORDER: np.arange(len(events))})
    return events.sort_values([CASE, TIME, _ORDER], kind="stable", ignore_index=True)


def pair_activities(events: pd.DataFrame) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Row positions of each activity's start and its end, and of unpaired ends.

    An activity ends by completing, or by being aborted or cancelled. Within a case, a robot and
    an activity name, each end closes the earliest start still
    open (events must be in time order). One pass over the tags, none over the samples.
    """
    open_starts: defaultdict[tuple[object, ...], deque[int]] = defaultdict(deque)
    starts: list[int] = []
    completes: list[int] = []
    orphans: list[int] = []
    keys = zip(events[CASE], events[ROBOT], events[ACTIVITY], strict=True)
    for position, (key, lifecycle) in enumerate(zip(keys, events[LIFECYCLE], strict=True)):
        if lifecycle == schema.START:
            open_starts[key].append(position)
        elif lifecycle in _CLOSING:
            if open_starts[key]:
                starts.append(open_starts[key].popleft())
                completes.append(position)
            else:
                orphans.append(position)
    return (
        np.asarray(starts, dtype=np.int64),
        np.asarray(completes, dtype=np.int64),
        np.asarray(orphans, dtype=np.int64),
    )


def inprogress(
    events: pd.DataFrame, starts: np.ndarray, completes: np.ndarray, rate: float
) -> pd.DataFrame:
    """``inprogress`` rows every ``1/rate`` seconds strictly between each start and completion.

    They keep the activity's case, robot and name (not its message: they are not messages).
    """
    columns = [c for c in (CASE, ROBOT, schema.ROBOT_TYPE, ACTIVITY) if c in events]
    period = round(1e9 / rate) if rate > 0 else 0
    nanos = events[TIME].to_numpy("datetime64[ns]").view(np.int64)
    begin, end = nanos[starts], nanos[completes]
    counts = np.maximum((end - begin - 1) // period, 0) if period else np.zeros_like(begin)
    pair = np.repeat(np.arange(len(starts)), counts)
    step = np.arange(len(pair)) - np.repeat(np.cumsum(counts) - counts, counts) + 1
    rows = events.iloc[starts[pair]][columns].reset_index(drop=True)
    rows[TIME] = pd.to_datetime(begin[pair] + step * period, unit="ns", utc=True)
    rows[LIFECYCLE] = schema.NONE
    rows[STATE] = schema.INPROGRESS
    # after every tag that shares its timestamp, in time order within the activity
    rows[_ORDER] = len(events) + np.arange(len(rows))
    return rows


def upper_closest(events: pd.DataFrame, samples: pd.DataFrame) -> pd.DataFrame:
    """Each event with the values of its robot's first sample at or after it in the same case.

    An event after the robot's last sample takes that last sample (the recording stopped
    first); a robot without samples gets no values.
    """
    values = [c for c in samples.columns if c not in (*KEYS, TIME)]
    if not values:
        return events
    right = samples[[*KEYS, TIME, *values]].rename(columns={TIME: "_at"})
    right = _join_types(right.dropna(subset=["_at"]), "_at").sort_values("_at", kind="stable")
    left = events[[*KEYS, TIME]].assign(_row=np.arange(len(events)))
    left = _join_types(left, TIME).sort_values(TIME, kind="stable")
    joined = _asof(left, right, "forward")
    late = joined["_at"].isna().to_numpy()
    if late.any():
        joined.loc[late, values] = _asof(left[late], right, "backward")[values].to_numpy()
    joined = joined.sort_values("_row")
    enriched = events.drop(columns=[c for c in values if c in events])
    for column in values:
        enriched[column] = joined[column].to_numpy()
    return enriched


def _join_types(frame: pd.DataFrame, time: str) -> pd.DataFrame:
    """Keys and times of one type on both sides, as merge_asof requires."""
    return frame.astype({CASE: str, ROBOT: str, time: "datetime64[ns, UTC]"})


def _asof(left: pd.DataFrame, right: pd.DataFrame, direction: str) -> pd.DataFrame:
    return pd.merge_asof(
        left, right, left_on=TIME, right_on="_at", by=KEYS, direction=direction
    ).set_index(left.index)


def _orphan_message(orphans: pd.DataFrame) -> str:
    examples = "; ".join(
        f"{row[ACTIVITY]} of {row[ROBOT]} in {row[CASE]} at {row[TIME].isoformat()}"
        for _, row in orphans.head(3).iterrows()
    )
    more = ", ..." if len(orphans) > 3 else ""
    return (
        f"{len(orphans)} complete event(s) have no start and are kept as they are "
        f"({examples}{more})."
    )


def robots_without_samples(tags: pd.DataFrame, samples: pd.DataFrame) -> list[str]:
    """``case/robot`` of each robot with tags but no sample of a perspective."""

    def pairs(frame: pd.DataFrame) -> set[tuple[str, str]]:
        return set(frame[KEYS].drop_duplicates().itertuples(index=False))

    return sorted(f"{case}/{robot}" for case, robot in pairs(tags) - pairs(samples))
