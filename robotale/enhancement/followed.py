"""What a robot did after a moment: its next activities, and when its last one completed.

A low-battery moment and a lost message both ask it of the robot's activity instances in the
case. Every moment is answered at once by binary search, with no join of each moment against
all of its robot's instances.
"""

from __future__ import annotations

import numpy as np
import pandas as pd

from robotale.discovery.instances import START_TIMESTAMP
from robotale.enhancement.context import sorted_distinct
from robotale.enhancement.performance import ARROW
from robotale.eventlog.schema import ACTIVITY, TIMESTAMP


def what_followed(
    instances: pd.DataFrame, moments: pd.DataFrame, on: list[str], at: str, following: int
) -> pd.DataFrame:
    """Per row of ``moments`` (its ``on`` columns name the instances it is about, such as case
    and robot, matched as :func:`pandas.merge` matches them; ``at`` its time): ``then``, the
    first ``following`` of those instances that started after ``at``, in the instances' order
    (start, then position), their activities joined by arrows ('' when none); and ``last_end``, the
    latest completion among all of them (NaT when none)."""
    block, moment_block = _blocks(instances, moments, on)
    starts = _nanoseconds(instances[START_TIMESTAMP])
    times = _nanoseconds(moments[at])
    # one sorted key per instance: its block, then its start's rank among all starts, so one
    # binary search finds a moment's first instance that starts after it
    distinct = sorted_distinct(starts)
    width = len(distinct) + 1
    order = np.lexsort((np.arange(len(block)), starts, block))
    keys = block[order] * width + np.searchsorted(distinct, starts[order])
    wanted = moment_block * width + np.searchsorted(distinct, times, side="right")
    first = np.searchsorted(keys, wanted)
    names = instances[ACTIVITY].astype(str).to_numpy(object)[order]
    known = (moment_block >= 0) & (times != np.iinfo(np.int64).min)
    then = np.full(len(moments), "", dtype=object)
    for step in range(following):
        at_step = np.minimum(first + step, max(len(order) - 1, 0))
        inside = known & (first + step < len(order))
        inside &= block[order][at_step] == moment_block
        # the steps of a moment run on consecutively: past its block, all later ones are too
        joined = names[at_step] if step == 0 else then + ARROW + names[at_step]
        then = np.where(inside, joined, then)
    ends = instances[TIMESTAMP].groupby(block).max()
    last_end = ends.reindex(np.where(moment_block >= 0, moment_block, -1)).to_numpy()
    return pd.DataFrame({"then": then, "last_end": last_end}, index=moments.index)


def _blocks(
    instances: pd.DataFrame, moments: pd.DataFrame, on: list[str]
) -> tuple[np.ndarray, np.ndarray]:
    """A number per instance for its ``on`` values, and each moment's (-1: none matches)."""
    block = instances.groupby(on, sort=False, dropna=False).ngroup().to_numpy(np.int64)
    named = instances[on].assign(_block=block).drop_duplicates(on)
    found = moments[on].merge(named, on=on, how="left")["_block"]
    return block, found.fillna(-1).to_numpy(np.int64)


def _nanoseconds(times: pd.Series) -> np.ndarray:
    """Times as UTC nanoseconds (NaT as the smallest integer)."""
    utc = pd.to_datetime(times, utc=True).dt.tz_localize(None)
    return utc.to_numpy("datetime64[ns]").view(np.int64)
