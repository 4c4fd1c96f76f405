"""The aggregates of one step, computed in pandas from the nodes it collapses.

:func:`aggregate_table` takes one row per node (its node id and the properties the step reads;
times as Unix nanoseconds) and returns one row per aggregate: its id and name, how many
nodes it replaces and which, the group-by values and the attribute aggregations. The
derived keys of robot logs (grid cell, region, time window, value band) are computed here.
"""

from __future__ import annotations

import datetime as dt
import itertools
from collections import Counter
from collections.abc import Callable, Sequence

import numpy as np
import pandas as pd
from neo4j.time import DateTime

from robotale.ekg.spec import AggrStep, AttrAggr, GroupKey
from robotale.errors import InputError

#: where a region key puts a point that lies in none of the areas
OUTSIDE = "outside"
#: how a missing group-by value shows in an aggregate's name
UNKNOWN = "unknown"


def aggregate_table(
    step: AggrStep, number: int, nodes: pd.DataFrame, times: set[str]
) -> pd.DataFrame:
    """One row per aggregate of ``nodes`` (columns ``node`` and the properties the step reads;
    the properties in ``times`` hold Unix nanoseconds): ``id``, ``name``, ``count``,
    ``members`` (node ids), a column per group key and per attribute output."""
    group, names, firsts = _groups(step.group_by, nodes, times)
    counts = np.bincount(group, minlength=len(names))
    # each aggregate's members in the nodes' order: one stable sort, then split
    order = np.argsort(group, kind="stable")
    ordered = nodes["node"].to_numpy(dtype=np.int64)[order]
    members = np.split(ordered, np.cumsum(counts)[:-1]) if len(names) else []
    table = pd.DataFrame(
        {"name": names, "count": counts, "members": pd.Series(members, dtype=object)}
    )
    for key, values in zip(step.group_by, firsts, strict=True):
        table[key.name] = values
    for attr in step.attr_aggrs:
        for output, found in attribute_values(attr, nodes[attr.name], group, attr.name in times):
            table[output] = found
    table.insert(0, "id", [f"{number}:{name}" for name in names])
    return table


def _groups(
    keys: Sequence[GroupKey], nodes: pd.DataFrame, times: set[str]
) -> tuple[np.ndarray, np.ndarray, list[np.ndarray]]:
    """The aggregate of each node (codes in the order of the aggregates' names), the names
    (the key values joined by ``|``, a missing one as :data:`UNKNOWN`) and, per key, each
    aggregate's first value of it that is not missing.

    Each key's values are coded once as integers and only each combination's first row is
    turned into text: a name per node cost more than the rest of the grouping. Combinations
    whose names are the same text are one aggregate, as when the names themselves were grouped.
    """
    coded = [_key_codes(key, nodes, times) for key in keys]
    combined = np.zeros(len(nodes), dtype=np.int64)
    for codes, values in coded:  # re-coded after each key: the integers stay below len(nodes)
        combined = pd.factorize(combined * (len(values) + 1) + codes + 1)[0].astype(np.int64)
    _, first_rows, combination = np.unique(combined, return_index=True, return_inverse=True)
    texts = [
        [UNKNOWN if c < 0 else str(values[c]) for c in codes[first_rows]] for codes, values in coded
    ]
    labels = ["|".join(parts) for parts in zip(*texts, strict=True)] if texts else []
    by_name, names = pd.factorize(np.asarray(labels, dtype=object), sort=True)
    group = by_name.astype(np.int64)[combination.reshape(-1)]
    firsts = []
    for codes, values in coded:
        rows = np.flatnonzero(codes >= 0)
        found, at = np.unique(group[rows], return_index=True)  # rows ascend: the first row
        first = np.full(len(names), None, dtype=object)
        first[found] = values[codes[rows[at]]]
        firsts.append(first)
    return group, np.asarray(names, dtype=object), firsts


def _key_codes(
    key: GroupKey, nodes: pd.DataFrame, times: set[str]
) -> tuple[np.ndarray, np.ndarray]:
    """The value of ``key`` for each node as a code (-1: missing) into the distinct values."""
    if key.kind == "property":  # coded as the column holds them, the distinct values shown
        codes, uniques = pd.factorize(nodes[key.inputs[0]])
        shown = pd.Series(np.asarray(uniques, dtype=object), dtype=object)
        values = _property(key, pd.DataFrame({key.inputs[0]: shown}), times)
    else:
        codes, uniques = pd.factorize(group_values(key, nodes, times))
        values = pd.Series(np.asarray(uniques, dtype=object), dtype=object)
    return codes.astype(np.int64), np.asarray([_plain(v) for v in values], dtype=object)


def group_values(key: GroupKey, nodes: pd.DataFrame, times: set[str]) -> pd.Series:
    """The value of ``key`` for each node (None where the node lacks what the key reads)."""
    return _GROUPERS[key.kind](key, nodes, times)


def _property(key: GroupKey, nodes: pd.DataFrame, times: set[str]) -> pd.Series:
    values = nodes[key.inputs[0]]
    if key.inputs[0] in times:
        return _iso(values)
    return values.astype(object).where(values.notna(), None)


def _grid(key: GroupKey, nodes: pd.DataFrame, times: set[str]) -> pd.Series:
    x, y = (np.floor(_numbers(nodes[c]) / key.size) for c in key.inputs)
    cells = [
        None if np.isnan(i) or np.isnan(j) else f"{int(i)},{int(j)}"
        for i, j in zip(x, y, strict=True)
    ]
    return pd.Series(cells, index=nodes.index, dtype=object)


def _band(key: GroupKey, nodes: pd.DataFrame, times: set[str]) -> pd.Series:
    lower = np.floor(_numbers(nodes[key.inputs[0]]) / key.size) * key.size
    return pd.Series(lower, index=nodes.index).astype(object).where(~np.isnan(lower), None)


def _window(key: GroupKey, nodes: pd.DataFrame, times: set[str]) -> pd.Series:
    if key.inputs[0] in times:  # nanoseconds, in integers: floats would blur the bounds
        values = pd.to_numeric(nodes[key.inputs[0]]).astype("Int64")
        width = round(key.size * 1_000_000_000)
        return _iso((values // width) * width)
    lower = np.floor(_numbers(nodes[key.inputs[0]]) / key.size) * key.size
    return pd.Series(lower, index=nodes.index).astype(object).where(~np.isnan(lower), None)


def _regions(key: GroupKey, nodes: pd.DataFrame, times: set[str]) -> pd.Series:
    x, y = (_numbers(nodes[c]) for c in key.inputs)
    found = np.full(len(nodes), OUTSIDE, dtype=object)
    free = np.ones(len(nodes), dtype=bool)
    for name, corners in key.areas:  # the first area that holds a point names it
        inside = free & _inside(x, y, np.asarray(corners))
        found[inside] = name
        free &= ~inside
    found[np.isnan(x) | np.isnan(y)] = None
    return pd.Series(found, index=nodes.index, dtype=object)


def _inside(x: np.ndarray, y: np.ndarray, corners: np.ndarray) -> np.ndarray:
    """Whether each point lies in the polygon (even-odd rule; a point on the lower or left
    edge of a box is inside, one on the upper or right edge is not)."""
    inside = np.zeros(len(x), dtype=bool)
    for (x1, y1), (x2, y2) in zip(corners, np.roll(corners, -1, axis=0), strict=True):
        if y1 == y2:
            continue
        crosses = (y1 <= y) != (y2 <= y)
        at = x1 + (y - y1) * (x2 - x1) / (y2 - y1)
        inside ^= crosses & (x < at)
    return inside


def _numbers(values: pd.Series) -> np.ndarray:
    numbers: np.ndarray = pd.to_numeric(values, errors="coerce").to_numpy(dtype=float)
    return numbers


def _iso(nanoseconds: pd.Series) -> pd.Series:
    moments = pd.to_datetime(pd.to_numeric(nanoseconds).astype("Int64"), unit="ns", utc=True)
    text = moments.dt.strftime("%Y-%m-%dT%H:%M:%S.%fZ")
    return text.astype(object).where(moments.notna(), None)


_GROUPERS: dict[str, Callable[[GroupKey, pd.DataFrame, set[str]], pd.Series]] = {
    "property": _property,
    "grid": _grid,
    "band": _band,
    "window": _window,
    "regions": _regions,
}


def attribute_values(
    attr: AttrAggr, values: pd.Series, labels: np.ndarray, is_time: bool
) -> list[tuple[str, list[object]]]:
    """(aggregate property, value per group, groups in the order of their labels: the
    aggregates' names, or their codes) for one attribute aggregation. Missing values are
    left out, as Cypher's aggregating functions leave out nulls."""
    outputs = attr.outputs()
    if attr.function == "MULTISET":
        found = _text_multisets(values, labels)
        if found is None:
            found = [multiset(part) for _, part in values.groupby(labels, sort=True)]
        return [(outputs[0], found)]
    if attr.function in ("SUM", "AVG"):
        numbers = pd.to_numeric(values, errors="coerce")
        if (numbers.isna() & values.notna()).any():
            raise InputError(
                f"{attr.function} of {attr.name!r} needs numbers, and some nodes hold "
                f"{values[numbers.isna() & values.notna()].iloc[0]!r}."
            )
        found = numbers.groupby(labels, sort=True).agg("sum" if attr.function == "SUM" else "mean")
        return [(outputs[0], [None if pd.isna(v) else _plain(v) for v in found])]
    if is_time:  # nanoseconds as integers: grouped as numbers, not as Python objects
        values = pd.to_numeric(values).astype("Int64")
    hows = ["min", "max"] if attr.function == "MINMAX" else [attr.function.lower()]
    grouped = values.groupby(labels, sort=True)
    return [
        (out, _extreme(grouped.agg(how), is_time)) for out, how in zip(outputs, hows, strict=True)
    ]


def _extreme(found: pd.Series, is_time: bool) -> list[object]:
    values = [None if _missing(v) else _plain(v) for v in found]
    if is_time:  # the earliest or latest time, as a time again
        return [None if v is None else _moment(int(v)) for v in values]  # type: ignore[call-overload]
    return values


def _moment(nanoseconds: int) -> DateTime:
    """A Unix time in nanoseconds as a Neo4j time in UTC (Python's own stops at microseconds)."""
    t = pd.Timestamp(nanoseconds, unit="ns", tz="UTC")
    return DateTime(t.year, t.month, t.day, t.hour, t.minute, t.second,
                    t.microsecond * 1000 + t.nanosecond, tzinfo=dt.UTC)  # fmt: skip


def multiset(values: Sequence[object] | pd.Series) -> list[str]:
    """OCEAN's MULTISET: each distinct value with how often it occurs, as ``value:count``,
    in the order of the values' text."""
    counts = Counter(str(_plain(v)) for v in values if not _missing(v))
    return [f"{value}:{count}" for value, count in sorted(counts.items())]


def _text_multisets(values: pd.Series, labels: np.ndarray) -> list[object] | None:
    """:func:`multiset` of each group of ``labels`` (in the order of ``groupby(labels,
    sort=True)``) when every value is text (an entity's ids are), counted on integer codes:
    a Counter per group cost a Python call per value. None for other values, whose text may
    join values that are unequal (``1`` and ``"1"``)."""
    if pd.api.types.infer_dtype(values, skipna=True) not in ("string", "empty"):
        return None
    groups, names = pd.factorize(labels, sort=True)  # groupby's order; -1: no group
    # sorted as Python sorts texts (by code point), the order multiset() writes them in
    codes, texts = pd.factorize(values, sort=True)  # -1: missing, left out
    keep = (groups >= 0) & (codes >= 0)
    width = max(len(texts), 1)
    pairs, counts = np.unique(
        groups[keep].astype(np.int64) * width + codes[keep], return_counts=True
    )
    group, text = np.divmod(pairs, width)
    words = np.asarray(texts, dtype=object)[text]
    items = [f"{word}:{count}" for word, count in zip(words, counts.tolist(), strict=True)]
    bounds = np.searchsorted(group, np.arange(len(names) + 1)).tolist()
    lists: list[object] = [items[a:b] for a, b in itertools.pairwise(bounds)]
    return lists


def _missing(value: object) -> bool:
    return value is None or value is pd.NA or (isinstance(value, float) and np.isnan(value))


def _plain(value: object) -> object:
    """numpy scalars as Python ones, which the driver sends."""
    return value.item() if isinstance(value, np.generic) else value
