"""A checked ``where`` (:mod:`robotale.ekg.where`) evaluated on a table of nodes in pandas,
with the meaning Neo4j gives the same condition: a node lacking a property (a missing value)
makes a comparison unknown; ``and``, ``or`` and ``not`` follow three-valued logic; a value of
another kind than the property's (a text against a number, a date against a time) is never
equal and never ordered; only the rows where the whole condition is true are kept.

An aggregation step over events reads the events from the log's columnar copy rather than the
graph, so its filter runs here; a step over entities still runs it in Neo4j.
"""

from __future__ import annotations

import datetime as dt
import operator
from collections.abc import Callable
from typing import Any

import numpy as np
import pandas as pd

from robotale.ekg.where import Condition

_ORDER: dict[str, Callable[[Any, Any], Any]] = {
    "=": operator.eq,
    "<>": operator.ne,
    "<": operator.lt,
    "<=": operator.le,
    ">": operator.gt,
    ">=": operator.ge,
}


def matching(condition: Condition, nodes: pd.DataFrame) -> np.ndarray:
    """Which rows of ``nodes`` (a column per property) pass ``condition``."""
    if condition.tree is None:
        return np.ones(len(nodes), dtype=bool)
    truth = _truth(condition.tree, nodes)
    found: np.ndarray = truth.fillna(False).to_numpy(dtype=bool)
    return found


def _truth(tree: Any, nodes: pd.DataFrame) -> pd.Series:
    """The condition per row as a nullable boolean (missing: unknown)."""
    kind = tree[0]
    if kind in ("and", "or"):
        parts = [_truth(part, nodes) for part in tree[1]]
        result = parts[0]
        for part in parts[1:]:
            result = (result & part) if kind == "and" else (result | part)  # Kleene logic
        return result
    if kind == "not":
        return ~_truth(tree[1], nodes)
    column = _column(nodes, tree[1])
    if kind in ("null", "not null"):
        missing = column.isna().to_numpy()
        return pd.Series(missing if kind == "null" else ~missing, dtype="boolean")
    if kind == "in":
        result = pd.Series(np.zeros(len(nodes), dtype=bool), dtype="boolean")
        for value in tree[2]:
            result = result | _compare(column, "=", value)
        return _unknown_where_missing(result, column)
    return _compare(column, kind, tree[2])


def _column(nodes: pd.DataFrame, name: str) -> pd.Series:
    if name in nodes.columns:
        return nodes[name].reset_index(drop=True)
    return pd.Series([None] * len(nodes), dtype=object)


def _compare(column: pd.Series, op: str, value: Any) -> pd.Series:
    """``column op value`` per row, as Neo4j compares a property with a value."""
    kind = _value_kind(value)
    typed = _typed(column, kind)
    if typed is None:  # a column of mixed values: each compared on its own
        found = [_compare_one(v, op, value) for v in column.astype(object).tolist()]
        return pd.Series(found, dtype="boolean")
    if typed is False:  # another kind: never equal, never ordered
        if op in ("=", "<>"):
            same = pd.Series(np.full(len(column), op == "<>"), dtype="boolean")
        else:
            same = pd.Series([pd.NA] * len(column), dtype="boolean")
        return _unknown_where_missing(same, column)
    compared = _ORDER[op](typed, _scalar(value, kind))
    result = pd.Series(np.asarray(compared.fillna(False), dtype=bool), dtype="boolean")
    return _unknown_where_missing(result, column)


def _unknown_where_missing(result: pd.Series, column: pd.Series) -> pd.Series:
    result = result.copy()
    result[column.isna().to_numpy()] = pd.NA
    return result


def _value_kind(value: Any) -> str:
    if isinstance(value, bool):
        return "bool"
    if isinstance(value, int | float):
        return "number"
    if isinstance(value, str):
        return "text"
    if isinstance(value, dt.datetime):
        return "time"
    return "date"


def _typed(column: pd.Series, kind: str) -> pd.Series | bool | None:
    """``column`` in a dtype that compares with a value of ``kind``; False when its values
    are of another kind, None when they are of several kinds."""
    dtype = column.dtype
    if isinstance(dtype, pd.CategoricalDtype):
        column = column.astype(dtype.categories.dtype)
        dtype = column.dtype
    if pd.api.types.is_bool_dtype(dtype):
        return column.astype("boolean") if kind == "bool" else False
    if pd.api.types.is_numeric_dtype(dtype):
        if kind != "number":
            return False
        return column.astype("Int64" if pd.api.types.is_integer_dtype(dtype) else "Float64")
    if isinstance(dtype, pd.DatetimeTZDtype):
        return column if kind == "time" else False
    if pd.api.types.is_datetime64_dtype(dtype):  # a time without a zone: Neo4j's local time
        return False
    inferred = pd.api.types.infer_dtype(column, skipna=True)
    if inferred in ("string", "empty"):
        return column.astype("string") if kind == "text" else False
    return None


def _scalar(value: Any, kind: str) -> Any:
    return pd.Timestamp(value) if kind == "time" else value


def _compare_one(found: Any, op: str, value: Any) -> bool | None:
    if found is None or found is pd.NA or (isinstance(found, float) and np.isnan(found)):
        return None
    if isinstance(found, np.generic):
        found = found.item()
    if isinstance(found, pd.Timestamp):
        found = found.to_pydatetime()
    if _value_kind(found) != _value_kind(value):
        return (op == "<>") if op in ("=", "<>") else None
    if isinstance(found, dt.datetime) and (found.tzinfo is None) != (value.tzinfo is None):
        return (op == "<>") if op in ("=", "<>") else None
    return bool(_ORDER[op](found, value))
