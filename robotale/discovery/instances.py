"""Activity instances: a start event paired with its complete event.

Tags mark where an activity starts and where it completes; control flow is about the activity
instances those pairs delimit. Pairing follows pm4py's interval logs (first in, first out per
activity), but per robot and per instance key (``execution_id`` or ``concept:instance`` when
the log has one, otherwise ``msg_id``), because robots run at the same time within one case
and a message activity's start and complete always share the message id. ``inprogress`` rows
carry continuous data and are never instances; an instant event (lifecycle ``none``, such as a
timer firing) is an instance that starts and completes at once. An activity interrupted or
cancelled (lifecycle ``aborted``/``cancelled``, XES' ``ate_abort``/``pi_abort``/``withdraw``)
ends there: it is a finished instance whose end keeps that lifecycle (:func:`interrupted`).
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
import pandas as pd

from robotale.eventlog.reading import LIFECYCLE_VALUES
from robotale.eventlog.schema import (
    ABORTED,
    ACTIVITY,
    CANCELLED,
    CASE,
    COMPLETE,
    INPROGRESS,
    LIFECYCLE,
    MSG_ID,
    ROBOT,
    START,
    STATE,
    TIMESTAMP,
)

#: pm4py's column for the start of an interval event.
START_TIMESTAMP = "start_timestamp"
#: columns naming an activity instance (a start and its complete share the value), in the
#: order they are looked for: robotale's own, XES's lifecycle instance, the message id.
INSTANCE_KEYS = ("execution_id", "concept:instance", MSG_ID)
DURATION = "duration"
FINISHED = "finished"
#: False for a completion whose start the log does not have: its duration is unknown (0 here),
#: so the time before it mixes the activity's own work with any wait.
START_KNOWN = "start_known"


#: what a row's lifecycle means for pairing, as a small code (:func:`_kinds`)
_OTHER, _START, _COMPLETE, _INSTANT = 0, 1, 2, 3
_KIND_OF = {START: _START, COMPLETE: _COMPLETE, "none": _INSTANT}


def control_flow_events(log: pd.DataFrame) -> pd.DataFrame:
    """The start, complete and instant events of ``log`` (no ``inprogress`` rows)."""
    return log[_control_flow(log, _kinds(log))]


def _control_flow(log: pd.DataFrame, kinds: np.ndarray) -> np.ndarray:
    """Which rows of ``log`` (``kinds``: their meanings, :func:`_kinds`) are starts,
    completes or instants."""
    keep = kinds != _OTHER
    if STATE in log.columns:
        keep &= log[STATE].astype("string").fillna("").str.lower().ne(INPROGRESS).to_numpy(bool)
    return keep


def activity_instances(log: pd.DataFrame, carry: Sequence[str] = ()) -> pd.DataFrame:
    """One row per activity instance, ordered by case and start (ties: as :func:`in_tie_order`
    orders the events of one moment).

    Columns: the completing event's columns, plus ``start_timestamp``, ``time:timestamp`` (the
    completion), ``duration`` in seconds, ``finished`` and ``start_known``; for every column
    named in ``carry`` its value at the start as ``start_<column>`` (a battery level, say). A
    start that never completes is an unfinished instance (no completion, no duration); a
    completion without a start, and an instant event, starts when it completes.
    """
    # the lifecycle's meanings worked out once, as small codes kept beside the rows as they
    # are chosen and ordered
    kinds = _kinds(log)
    keep = _control_flow(log, kinds)
    # the rows are chosen and ordered on the few columns that order and pair them; the
    # log's other columns are taken once, for the instances
    reading = [c for c in (CASE, ROBOT, ACTIVITY, TIMESTAMP, *INSTANCE_KEYS) if c in log.columns]
    at = np.flatnonzero(keep)
    events, kinds = log[reading].iloc[at], kinds[at]
    if events.empty:
        return _empty_instances(log)
    starts = kinds == _START
    order = _tie_positions(events, starts)
    if order is not None:
        events, kinds, at = events.iloc[order], kinds[order], at[order]
        starts = starts[order]
    completes = kinds == _COMPLETE
    begun = _paired_rows(_group_codes(events), starts, completes)
    # one row per instance: each completion or instant event, and each start nothing paired;
    # ``begun`` holds the row it started at (its own where the start is not in the log)
    rows = np.flatnonzero(~starts | (begun == -1))
    opened = np.where(starts[rows] | (begun[rows] == -1), rows, begun[rows])
    finished = ~starts[rows]
    # in case and start order, instances that start at once by the start event's position
    cases = sort_codes(events[CASE].iloc[rows]) if CASE in events.columns else 0
    when = _ticks(events[TIMESTAMP].iloc[opened]).copy()
    when[events[TIMESTAMP].iloc[opened].isna().to_numpy()] = np.iinfo(np.int64).max
    ranked = np.lexsort((opened, when, cases))
    rows, opened, finished = rows[ranked], opened[ranked], finished[ranked]

    instances = log.iloc[at[rows]].reset_index(drop=True)
    read_at_start = list(dict.fromkeys([TIMESTAMP, *carry]))
    at_start = log[read_at_start].iloc[at[opened]].set_axis(instances.index)
    instances[START_TIMESTAMP] = at_start[TIMESTAMP]
    for column in carry:
        instances[f"start_{column}"] = at_start[column]
    ended = instances[TIMESTAMP].where(finished, pd.NaT)
    instances[TIMESTAMP] = ended
    instances[FINISHED] = finished
    instant = kinds[rows] == _INSTANT
    instances[START_KNOWN] = ~finished | (opened != rows) | instant
    instances[DURATION] = (ended - instances[START_TIMESTAMP]).dt.total_seconds()
    return instances


def _group_codes(events: pd.DataFrame) -> np.ndarray:
    """One integer per event naming its pairing group (:func:`_pairing_keys`; a missing
    value a value of its own), from each key column's codes."""
    codes = np.zeros(len(events), dtype=np.int64)
    for column in _pairing_keys(events):
        column_codes, uniques = pd.factorize(events[column], use_na_sentinel=True)
        codes = codes * (len(uniques) + 1) + (column_codes + 1)
        codes = pd.factorize(codes)[0].astype(np.int64)  # kept small: no overflow
    return codes


def _paired_rows(group: np.ndarray, starts: np.ndarray, completes: np.ndarray) -> np.ndarray:
    """For each completion, the row of the start it pairs with (-1: none); for each start,
    the row of its completion (-1: it never completed); -1 for other events.

    Within a group (events in time order) first in, first out: the number of open starts
    follows q_i = max(q_(i-1) + d_i, 0) with d = +1 for a start and -1 for a completion, in
    the closed form S_i - min(0, min_(k<=i) S_k) over the running sum S. A completion is
    matched when a start was open before it, and the k-th matched completion of a group
    pairs with the group's k-th start."""
    paired = np.full(len(group), -1, dtype=np.int64)
    by_group = np.argsort(group, kind="stable")  # each group's events, in time order
    g = group[by_group]
    step = starts[by_group].astype(np.int64) - completes[by_group].astype(np.int64)
    first = np.ones(len(g), dtype=bool)
    first[1:] = g[1:] != g[:-1]
    begin = np.maximum.accumulate(np.where(first, np.arange(len(g)), 0))
    total = np.cumsum(step)
    running = total - np.where(begin > 0, total[begin - 1], 0)  # S within the group
    lowest = _group_cummin(running, first)
    open_now = running - np.minimum(lowest, 0)
    open_before = np.where(first, 0, np.roll(open_now, 1))
    matched = completes[by_group] & (open_before > 0)
    is_start = starts[by_group]
    # the k-th matched completion of each group and the group's k-th start
    match_rank = _rank_in_group(matched, begin)
    start_at = np.flatnonzero(is_start)
    # where each group's starts begin in ``start_at``
    starts_before = np.cumsum(is_start) - is_start
    offset = starts_before[begin]
    pairs = np.flatnonzero(matched)
    opened = start_at[offset[pairs] + match_rank[pairs]]
    paired[by_group[pairs]] = by_group[opened]
    paired[by_group[opened]] = by_group[pairs]
    return paired


def _group_cummin(values: np.ndarray, first: np.ndarray) -> np.ndarray:
    """The running minimum of ``values`` restarting where ``first`` is set."""
    return pd.Series(values).groupby(np.cumsum(first)).cummin().to_numpy()


def _rank_in_group(flags: np.ndarray, begin: np.ndarray) -> np.ndarray:
    """For each set flag, how many flags of its group come before it."""
    count = np.cumsum(flags)
    return count - flags - np.where(begin > 0, count[begin - 1], 0)


def sort_codes(values: pd.Series) -> np.ndarray:
    """Integers that order as pandas sorts ``values`` (a missing value last)."""
    codes, uniques = pd.factorize(values, sort=True)
    return np.where(codes == -1, len(uniques), codes)


def in_tie_order(events: pd.DataFrame) -> pd.DataFrame:
    """The events in time order, those at the same moment by a rule: a start before any other
    event, then by robot, then as the file has them. A start first pairs each completion with
    the instance it ends however the rows of one moment were written; robots in name order
    make the interleaving of robots independent of the file. Within one robot the file's
    order stays: a robot's engine tags its events one after the other, so a sequence of
    activities that take no time (a simulated clock) keeps its order, which the activities'
    names would not."""
    order = _tie_positions(events, _kinds(events) == _START)
    return events if order is None else events.iloc[order]


def _tie_positions(events: pd.DataFrame, starts: np.ndarray) -> np.ndarray | None:
    """The positions of ``events`` (``starts``: which are starts) in the order of
    :func:`in_tie_order`; ``None`` when they are in it already."""
    order = None
    if not events[TIMESTAMP].is_monotonic_increasing:  # logs usually come in time order
        # as a stable sort of the column orders them (a missing time last)
        stamps = events[TIMESTAMP].reset_index(drop=True)
        order = stamps.sort_values(kind="stable").index.to_numpy()
    times = _ticks(events[TIMESTAMP] if order is None else events[TIMESTAMP].iloc[order])
    same = times[1:] == times[:-1]
    if not same.any():
        return order
    tied = np.zeros(len(events), dtype=bool)
    tied[1:] |= same
    tied[:-1] |= same
    rows = np.flatnonzero(tied)
    at = rows if order is None else order[rows]  # the tied rows' positions in ``events``
    keys = [np.arange(len(rows))]  # the file's order: the last tie-break
    if ROBOT in events.columns:
        values = events[ROBOT].iloc[at].astype("string").fillna("")
        keys.append(pd.factorize(values, sort=True)[0])
    keys.append((~starts[at]).astype(np.int8))
    keys.append(times[rows])
    ordered = np.arange(len(events)) if order is None else order.copy()
    ordered[rows] = at[np.lexsort(keys)]
    return ordered


def _ticks(times: pd.Series) -> np.ndarray:
    """The times as integers (of their own unit) that compare as the times do."""
    values = times.array
    if not hasattr(values, "asi8"):  # times of several offsets, kept as objects
        values = pd.to_datetime(times, utc=True).array
    return np.asarray(values.asi8)


def _kinds(log: pd.DataFrame) -> np.ndarray:
    """What each row's lifecycle means for pairing: :data:`_START`, :data:`_COMPLETE`,
    :data:`_INSTANT` or :data:`_OTHER` (an ``inprogress`` sample, say), worked out once per
    distinct value; a row without a lifecycle completes."""
    if LIFECYCLE not in log.columns:
        return np.full(len(log), _COMPLETE, dtype=np.int8)
    codes, meaning = _meanings(log[LIFECYCLE])
    # an aborted or cancelled activity (XES' ``ate_abort`` ...) ended all the same: it pairs
    # with its start (the row keeps its own lifecycle, so the outcome stays visible)
    lowered = meaning.replace({ABORTED: COMPLETE, CANCELLED: COMPLETE})
    kinds = [_KIND_OF.get(value, _OTHER) for value in lowered.tolist()]
    return np.array([*kinds, _COMPLETE], dtype=np.int8)[codes]


def interrupted(instances: pd.DataFrame) -> pd.Series:
    """Which instances ended aborted or cancelled (interrupted) rather than completed."""
    if LIFECYCLE not in instances.columns:
        return pd.Series(False, index=instances.index)
    codes, meaning = _meanings(instances[LIFECYCLE])
    stopped = meaning.isin([ABORTED, CANCELLED]).to_numpy(bool)
    return pd.Series(np.append(stopped, False)[codes], index=instances.index)


def _meanings(lifecycle: pd.Series) -> tuple[np.ndarray, pd.Series]:
    """Codes of the lifecycle values (-1: missing) and what each distinct value means, worked
    out once per value (a log repeats a handful of them)."""
    # a text column factorised as it is: as Python objects first, a million rows cost 5x more
    text = isinstance(lifecycle.dtype, pd.StringDtype)
    codes, uniques = pd.factorize(lifecycle if text else lifecycle.astype(object))
    lowered = pd.Series(uniques, dtype="string").str.lower()
    meaning = lowered.map(lambda value: LIFECYCLE_VALUES.get(value, value), na_action="ignore")
    return codes, meaning.astype("string")


def _pairing_keys(events: pd.DataFrame) -> list[str]:
    keys = [column for column in (CASE, ROBOT, ACTIVITY) if column in events.columns]
    for instance_key in INSTANCE_KEYS:
        if instance_key in events.columns:
            return [*keys, instance_key]
    return keys


def _empty_instances(log: pd.DataFrame) -> pd.DataFrame:
    empty = log.iloc[0:0].copy()
    empty[START_TIMESTAMP] = pd.Series(dtype=log[TIMESTAMP].dtype)
    empty[DURATION] = pd.Series(dtype=float)
    empty[FINISHED] = pd.Series(dtype=bool)
    empty[START_KNOWN] = pd.Series(dtype=bool)
    return empty
