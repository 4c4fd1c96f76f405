"""Filters applied to an event log before discovery (case, robot, robot type, time, activity)."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field

import pandas as pd

from robotale.errors import InputError
from robotale.eventlog.schema import ACTIVITY, CASE, ROBOT, ROBOT_TYPE, TIMESTAMP


@dataclass(frozen=True, slots=True)
class LogFilter:
    """Which events to keep; an empty selection keeps everything.

    ``start`` / ``end`` bound the events' timestamps (inclusive); a time without a zone is
    taken in the log's zone.
    """

    cases: Sequence[str] = field(default_factory=tuple)
    robots: Sequence[str] = field(default_factory=tuple)
    robot_types: Sequence[str] = field(default_factory=tuple)
    activities: Sequence[str] = field(default_factory=tuple)
    start: str | pd.Timestamp | None = None
    end: str | pd.Timestamp | None = None

    def is_empty(self) -> bool:
        chosen = (self.cases, self.robots, self.robot_types, self.activities)
        return not any(chosen) and self.start is None and self.end is None

    def describe(self) -> dict[str, object]:
        """The filter as plain data, for the ``info`` of a result."""
        described: dict[str, object] = {
            name: list(values)
            for name, values in (
                ("cases", self.cases),
                ("robots", self.robots),
                ("robot_types", self.robot_types),
                ("activities", self.activities),
            )
            if values
        }
        for name, value in (("start", self.start), ("end", self.end)):
            if value is not None:
                described[name] = str(value)
        return described


def filter_log(log: pd.DataFrame, selection: LogFilter | None = None) -> pd.DataFrame:
    """The events of ``log`` that ``selection`` keeps.

    Raises :class:`InputError` naming the filter when a filter matches no event, or when the
    log lacks the column a filter needs.
    """
    if selection is None or selection.is_empty():
        return log
    for column, values, what in (
        (CASE, selection.cases, "case"),
        (ROBOT, selection.robots, "robot"),
        (ROBOT_TYPE, selection.robot_types, "robot type"),
        (ACTIVITY, selection.activities, "activity"),
    ):
        if values:
            log = _keep_values(log, column, values, what)
    if selection.start is not None or selection.end is not None:
        log = _keep_window(log, selection.start, selection.end)
    return log


def _keep_values(log: pd.DataFrame, column: str, values: Sequence[str], what: str) -> pd.DataFrame:
    if column not in log.columns:
        raise InputError(f"cannot filter by {what}: the log has no {column!r} column.")
    wanted = {str(v) for v in values}
    present = log[column].astype("string")
    kept = log[present.isin(wanted).fillna(False).to_numpy(bool)]
    if kept.empty:
        known = sorted(present.dropna().unique())
        shown = ", ".join(known[:10]) + (" ..." if len(known) > 10 else "")
        raise InputError(
            f"no event has {what} {', '.join(sorted(wanted))}; the log's values are: {shown}."
        )
    return kept


def _keep_window(log: pd.DataFrame, start, end) -> pd.DataFrame:
    times = log[TIMESTAMP]
    low = _as_log_time(start, times, "start") if start is not None else None
    high = _as_log_time(end, times, "end") if end is not None else None
    keep = pd.Series(True, index=log.index)
    if low is not None:
        keep &= times >= low
    if high is not None:
        keep &= times <= high
    kept = log[keep.to_numpy(bool)]
    if kept.empty:
        raise InputError(
            f"no event lies between {low or 'the beginning'} and {high or 'the end'}; "
            f"the log runs from {times.min()} to {times.max()}."
        )
    return kept


def _as_log_time(value, times: pd.Series, which: str) -> pd.Timestamp:
    try:
        stamp = pd.Timestamp(value)
    except (ValueError, TypeError) as error:
        raise InputError(f"the {which} time {value!r} is not a date and time.") from error
    zone = getattr(times.dt, "tz", None)
    if stamp.tzinfo is None and zone is not None:
        stamp = stamp.tz_localize(zone)
    elif stamp.tzinfo is not None and zone is None:
        stamp = stamp.tz_convert(None)
    return stamp
