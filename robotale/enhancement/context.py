"""Tables several perspectives share, built once per log.

The perspectives all start from the same intermediate tables: the activity instances, each
robot's steps between them, case durations, variants and the message table. Each perspective
accepts a log or a :class:`LogAnalysis` of it; :func:`all_perspectives` hands one analysis to
all of them so those tables are computed once. A table is built the first time a perspective
asks for it and is then shared, so callers must never modify one in place.
"""

from __future__ import annotations

from collections.abc import Callable, Hashable, Sequence
from typing import Any

import numpy as np
import pandas as pd

from robotale.discovery.instances import INSTANCE_KEYS, activity_instances
from robotale.eventlog.schema import (
    ACTIVITY,
    BATTERY,
    CASE,
    LIFECYCLE,
    MSG_ID,
    MSG_ROLE,
    ROBOT,
    STATE,
    TIMESTAMP,
)

#: the columns the perspectives read from activity instances (with those a caller carries):
#: a wide log's other columns are not copied through every step of the pairing
INSTANCE_COLUMNS = (
    CASE,
    ROBOT,
    ACTIVITY,
    TIMESTAMP,
    LIFECYCLE,
    STATE,
    MSG_ID,
    MSG_ROLE,
    BATTERY,
    *INSTANCE_KEYS,
)


class LogAnalysis:
    """A log with the tables computed from it so far."""

    def __init__(self, log: pd.DataFrame) -> None:
        self.log = log
        self._tables: dict[Hashable, Any] = {}

    def shared(self, key: Hashable, build: Callable[[], Any]) -> Any:
        """The table named ``key``, built by ``build()`` the first time it is asked for."""
        if key not in self._tables:
            self._tables[key] = build()
        return self._tables[key]

    def __contains__(self, key: Hashable) -> bool:
        """Whether the table named ``key`` has been built."""
        return key in self._tables

    def built(self) -> list[Hashable]:
        """The names of the tables built so far."""
        return list(self._tables)

    def instances(self, carry: Sequence[str] = ()) -> pd.DataFrame:
        """:func:`~robotale.discovery.instances.activity_instances` of the log, with the
        columns of :data:`INSTANCE_COLUMNS` and ``carry``."""
        carry = tuple(carry)
        wanted = [c for c in self.log.columns if c in INSTANCE_COLUMNS or c in carry]
        return self.shared(
            ("instances", carry), lambda: activity_instances(self.log[wanted], carry)
        )


def analysis_of(source: pd.DataFrame | LogAnalysis) -> LogAnalysis:
    """``source`` itself when it is an analysis already, else a fresh one of the log."""
    return source if isinstance(source, LogAnalysis) else LogAnalysis(source)


def sorted_distinct(values: np.ndarray) -> np.ndarray:
    """The distinct ``values`` in ascending order, as :func:`numpy.unique` gives them: by a
    sort, which numpy's own hashing of integers with many distinct values is many times
    slower than."""
    ordered = np.sort(values)
    return ordered[np.r_[True, ordered[1:] != ordered[:-1]]] if len(ordered) else ordered


def row_keys(
    left: Sequence[pd.Series], right: Sequence[pd.Series]
) -> tuple[np.ndarray, np.ndarray] | None:
    """One integer per row of ``left`` and of ``right`` (columns of two tables, in the same
    order; ``right`` may be empty), equal where the rows' values are: rows matched by
    integers instead of an index of tuples. ``None`` when a value is missing (a caller matches
    those as its index would)."""
    n = len(left[0]) if left else 0
    keys = np.zeros(n + (len(right[0]) if right else 0), dtype=np.int64)
    for at, one in enumerate(left):
        parts = [one.reset_index(drop=True)] + ([right[at].reset_index(drop=True)] if right else [])
        codes, uniques = pd.factorize(pd.concat(parts, ignore_index=True) if right else parts[0])
        if (codes < 0).any():
            return None
        # renumbered after each column, so the combined key never outgrows an integer
        keys = pd.factorize(keys * (len(uniques) + 1) + codes)[0].astype(np.int64)
    return keys[:n], keys[n:]
