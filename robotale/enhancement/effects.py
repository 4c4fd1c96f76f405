"""How much longer the cases with something take than the cases without it, and how sure.

The confidence figure is the two-sided p-value of the Mann-Whitney U test (normal
approximation with tie and continuity corrections, as ``scipy.stats.mannwhitneyu(...,
method="asymptotic")``): the chance that durations as far apart arise when the thing makes no
difference. Rank tests suit case durations, which are skewed by a few long runs.
"""

from __future__ import annotations

import math

import numpy as np
import pandas as pd

from robotale.eventlog.schema import CASE

STATS = (
    "cases_with",
    "cases_without",
    "mean_with",
    "mean_without",
    "extra_mean",
    "extra_median",
    "p_value",
)


def compare_cases(members: pd.DataFrame, key: str, durations: pd.Series) -> pd.DataFrame:
    """Per value of ``key``: the cases it is in (``members``: rows of ``key`` and case) against
    the other cases of ``durations`` (seconds, indexed by case): counts, means, the extra mean
    and median seconds of the cases with it, and the p-value."""
    values = durations.to_numpy(float)
    pairs = members[[key, CASE]].drop_duplicates()
    where = durations.index.get_indexer(pairs[CASE])  # -1: a case without a duration
    known = where >= 0
    index = where[known]
    ranks = pd.Series(values).rank().to_numpy()
    frame = pd.DataFrame(
        {key: pairs[key].to_numpy()[known], "_d": values[index], "_r": ranks[index], "_i": index}
    )
    grouped = frame.groupby(key, sort=False)
    n, n_with = len(values), grouped.size()
    table = pd.DataFrame({"cases_with": n_with, "cases_without": n - n_with})
    sums = grouped["_d"].sum()
    table["mean_with"] = sums / n_with
    table["mean_without"] = (values.sum() - sums) / table["cases_without"].where(n_with < n)
    table["extra_mean"] = table["mean_with"] - table["mean_without"]
    medians_without = _medians_without(grouped["_i"], values)
    table["extra_median"] = grouped["_d"].median() - medians_without.reindex(table.index)
    table["p_value"] = _mann_whitney(grouped["_r"].sum(), n_with, values)
    return table


def _medians_without(positions, values: np.ndarray) -> pd.Series:
    """The median duration of the cases without each value (NaN when it is in every case).

    All values at once: with the durations sorted, a value's cases sit at sorted positions
    p_0 < p_1 < ...; the k-th smallest of the other cases is at k + t, where t counts the
    cases with p_i - i <= k (the other cases before p_i number p_i - i)."""
    n = len(values)
    order = np.argsort(values, kind="stable")
    sorted_values = values[order]
    place = np.empty(n, dtype=np.int64)
    place[order] = np.arange(n)
    frame = positions.obj.to_frame("_i").assign(_p=place[positions.obj.to_numpy(np.int64)])
    frame["_g"] = positions.ngroup().to_numpy()
    frame = frame.sort_values(["_g", "_p"], kind="stable")
    group = frame["_g"].to_numpy()
    before = frame["_p"].to_numpy() - frame.groupby("_g", sort=False).cumcount().to_numpy()
    size = np.bincount(group, minlength=positions.ngroups)
    others = n - size
    low, high = (others - 1) // 2, others // 2

    def kth_other(k: np.ndarray) -> np.ndarray:
        passed = np.bincount(group, weights=before <= k[group], minlength=len(k))
        at = np.clip(k + passed.astype(np.int64), 0, max(n - 1, 0))
        return sorted_values[at] if n else np.full(len(k), np.nan)

    medians = (kth_other(low) + kth_other(high)) / 2
    medians = np.where(others > 0, medians, math.nan)
    names = positions.size().index  # group keys in ngroup order
    return pd.Series(medians, index=names, dtype=float)


def _mann_whitney(rank_sums: pd.Series, n_with: pd.Series, values: np.ndarray) -> pd.Series:
    """Two-sided p-values from the rank sums of the cases with each value."""
    n = len(values)
    n_without = n - n_with
    u_with = rank_sums - n_with * (n_with + 1) / 2
    u = np.maximum(u_with, n_with * n_without - u_with)
    _, ties = np.unique(values, return_counts=True)
    tie_term = float((ties**3 - ties).sum()) / (n * (n - 1)) if n > 1 else 0.0
    sigma = np.sqrt(n_with * n_without / 12 * ((n + 1) - tie_term))
    z = (u - n_with * n_without / 2 - 0.5) / sigma.where(sigma > 0)
    return z.map(lambda x: min(1.0, math.erfc(x / math.sqrt(2))) if pd.notna(x) else math.nan)
