"""Which message latencies count as delayed, and the rule that said so.

Given a threshold (``--delay`` seconds), a latency above it is delayed. Without one, a latency
is delayed when it belongs to the slow mode of a two-mode (bimodal) distribution of its
channel's latencies (a channel: sender, receiver and message type), found as follows:

1. the latencies are compared on a log scale (a delay of 2 s beside deliveries of 20 ms is
   as clear as one of 20 s beside 200 ms), each taken as at least 1 ms;
2. they are split in two at the place that explains most of their variance (Otsu's split:
   the fast group below, the slow group above);
3. the slow group is delayed only when the split is a real gap: the split explains at least
   :data:`EXPLAINED` of the variance, the fastest slow latency is at least :data:`GAP` times
   the slowest fast one, and there are at least :data:`FEWEST` latencies.

Latencies that are all alike (one mode, however spread) fail 3 and nothing is delayed; a
long but continuous tail is no second mode either. The rule never looks at a fixed
percentile, so it neither invents delays in a log without any nor hides them when they are
common.
"""

from __future__ import annotations

import numpy as np
import pandas as pd

#: the share of the (log) latencies' variance the split must explain
EXPLAINED = 0.8
#: how many times slower the slow group must start than the fast group ends
GAP = 2.0
#: the fewest received messages of a type for its latencies to show two modes
FEWEST = 4
#: latencies below this (seconds) compare as this: clocks of a few microseconds apart
FLOOR = 0.001


def delay_rule(threshold: float | None) -> str:
    """The rule in words, for a report."""
    if threshold is not None:
        return f"a latency above {threshold:g} s (the threshold given)"
    return (
        "a latency in the slow mode of its channel's two-mode latency distribution "
        f"(split on log latency where it explains most variance; delayed only when the split "
        f"explains at least {EXPLAINED:.0%} of it, the slow mode starts at least {GAP:g}x "
        f"later than the fast one ends, and the channel has at least {FEWEST} received "
        "messages); latencies that are all alike have no delayed message"
    )


def delayed(latency: pd.Series, groups: pd.Series, threshold: float | None) -> pd.Series:
    """Per latency (missing: not received, never delayed), whether it is delayed: above
    ``threshold``, else in the slow mode of its group (see the module)."""
    if threshold is not None:
        return latency.gt(threshold)
    cut = slow_mode_starts(latency, groups)
    bound = pd.Series(groups.map(cut).to_numpy(float), index=latency.index)
    return latency.ge(bound).fillna(False).astype(bool)


def slow_mode_starts(latency: pd.Series, groups: pd.Series) -> dict:
    """Per group with a slow mode, its fastest slow latency (seconds)."""
    found = {}
    known = latency.notna().to_numpy(bool)
    frame = pd.DataFrame({"g": groups.to_numpy(object)[known], "v": latency.to_numpy(float)[known]})
    for name, values in frame.groupby("g", sort=False)["v"]:
        start = _slow_mode_start(np.sort(values.to_numpy(float)))
        if start is not None:
            found[name] = start
    return found


def _slow_mode_start(values: np.ndarray) -> float | None:
    if len(values) < FEWEST:
        return None
    logs = np.log10(np.maximum(values, FLOOR))
    total = float(((logs - logs.mean()) ** 2).sum())
    if total <= 0:
        return None
    n = len(logs)
    left = np.arange(1, n)  # the fast group: the first k values, k = 1 .. n-1
    sums = np.cumsum(logs)[:-1]
    mean_fast = sums / left
    mean_slow = (logs.sum() - sums) / (n - left)
    between = left * (n - left) / n * (mean_fast - mean_slow) ** 2
    k = int(np.argmax(between))
    fast_end, slow_start = values[k], values[k + 1]
    if between[k] / total < EXPLAINED or max(slow_start, FLOOR) < GAP * max(fast_end, FLOOR):
        return None
    return float(slow_start)
