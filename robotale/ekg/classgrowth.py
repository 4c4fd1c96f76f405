"""The class tables of a log that grows (:class:`GrowingClasses`), made of what is new.

A live log's update (:class:`~robotale.ekg.growing.GrowingLog`) is told how many first events
are the last update's, row for row, and no later event is older than they are. What those
events give the class tables then stays: each event's class and the classes in the order they
first appear, and every instance DF edge between two of them (no later event falls between
them in a chain), with its seconds. Each update keeps that and adds only the tail's part:
the classes of the tail's events, and its instance edges, whose seconds are inserted into the
sorted seconds of their class pair; the count, mean and exact median are computed again only
for the pairs the tail touched. The result equals :func:`~robotale.ekg.tables.class_tables`
of the whole log, its DF_C rows ordered by source, target and entity type.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field

import numpy as np
import pandas as pd

from robotale.ekg.tables import (
    ClassTables,
    GraphTables,
    _class_ids,
    _entries,
    _seconds_between,
)

#: a DF_C edge before its classes are rows: source class, target class, entity type
Pair = tuple[int, int, str]


@dataclass(frozen=True)
class GrowingClasses:
    """What the events of the last update gave the class tables of ``key``."""

    key: tuple[str, ...]
    codes: np.ndarray = field(default_factory=lambda: np.empty(0, dtype=np.int64))
    #: class id (its text) -> its row; the first event of each row, increasing
    ids: dict[str, int] = field(default_factory=dict)
    firsts: np.ndarray = field(default_factory=lambda: np.empty(0, dtype=np.int64))
    #: the instance DF edges, ordered by the later position of their ends: those positions,
    #: each edge's pair and seconds (those from a position on are a tail of the lists)
    last: np.ndarray = field(default_factory=lambda: np.empty(0, dtype=np.int64))
    pairs: tuple[Pair, ...] = ()
    seconds: np.ndarray = field(default_factory=lambda: np.empty(0, dtype=np.float64))
    #: each pair's seconds sorted, and its count, mean and median
    sorted_seconds: dict[Pair, np.ndarray] = field(default_factory=dict)
    values: dict[Pair, tuple[int, float, float]] = field(default_factory=dict)

    def grown(self, tables: GraphTables, same: int) -> tuple[GrowingClasses, ClassTables]:
        """The class tables of ``tables`` (its first ``same`` events those this was made
        of, no later one older than they are) and what to keep of them for the next."""
        if same == 0 and len(self.codes):  # nothing is kept: not one removal per edge held
            return GrowingClasses(self.key).grown(tables, 0)
        events = tables.events
        kept = int(np.searchsorted(self.firsts, same))
        ids = {text: code for text, code in self.ids.items() if code < kept}
        firsts = self.firsts[:kept].tolist()
        tail_codes = []
        for at, text in enumerate(_class_ids(events.iloc[same:], self.key).tolist(), same):
            code = ids.get(text)
            if code is None:
                code = ids[text] = len(firsts)
                firsts.append(at)
            tail_codes.append(code)
        codes = np.concatenate([self.codes[:same], np.array(tail_codes, dtype=np.int64)])
        last, pairs, seconds = self._tail_edges(tables, codes, same)
        cut = int(np.searchsorted(self.last, same))
        touched: dict[Pair, tuple[list[float], list[float]]] = {}
        for pair, s in zip(self.pairs[cut:], self.seconds[cut:].tolist(), strict=True):
            touched.setdefault(pair, ([], []))[0].append(s)
        for pair, s in zip(pairs, seconds.tolist(), strict=True):
            touched.setdefault(pair, ([], []))[1].append(s)
        sorted_seconds, values = dict(self.sorted_seconds), dict(self.values)
        for pair, (gone, new) in touched.items():
            now = _changed(sorted_seconds.get(pair), gone, new)
            if len(now):
                sorted_seconds[pair], values[pair] = now, _pair_values(now)
            else:
                sorted_seconds.pop(pair, None)
                values.pop(pair, None)
        kept_state = GrowingClasses(
            self.key,
            codes,
            ids,
            np.array(firsts, dtype=np.int64),
            np.concatenate([self.last[:cut], last]),
            self.pairs[:cut] + tuple(pairs),
            np.concatenate([self.seconds[:cut], seconds]),
            sorted_seconds,
            values,
        )
        return kept_state, kept_state._tables(tables)

    @property
    def kept_edges(self) -> int:
        """How many instance DF edges these tables hold (for tests)."""
        return len(self.pairs)

    def _tail_edges(
        self, tables: GraphTables, codes: np.ndarray, same: int
    ) -> tuple[np.ndarray, list[Pair], np.ndarray]:
        """The instance DF edges touching the events from ``same`` on, by the later position
        of their ends: those positions, their pairs, their seconds."""
        follows = tables.follows
        source, target = follows["source"].to_numpy(), follows["target"].to_numpy()
        last = np.maximum(source, target)
        tail = np.flatnonzero(last >= same)
        tail = tail[np.argsort(last[tail], kind="stable")]
        source, target = source[tail], target[tail]
        pairs = list(
            zip(
                codes[source].tolist(),
                codes[target].tolist(),
                follows["entityType"].take(tail).astype(str).tolist(),
                strict=True,
            )
        )
        return last[tail], pairs, _seconds_between(tables.events, source, target)

    def _tables(self, tables: GraphTables) -> ClassTables:
        events = tables.events
        texts = sorted(self.ids, key=self.ids.__getitem__)
        classes = (
            events[list(self.key)]
            .iloc[self.firsts]
            .reset_index(drop=True)
            .assign(id=np.array(texts, dtype=object))
        )
        pairs = sorted(self.values)
        counts = [self.values[p] for p in pairs]
        df_c = pd.DataFrame(
            {
                "source": np.array([p[0] for p in pairs], dtype=np.int64),
                "target": np.array([p[1] for p in pairs], dtype=np.int64),
                # with no edge, typed as class_tables types it (no entity type's name)
                "entityType": np.array([p[2] for p in pairs], dtype=object if pairs else np.int64),
                "count": np.array([v[0] for v in counts], dtype=np.int64),
                "meanSeconds": np.array([v[1] for v in counts], dtype=np.float64),
                "medianSeconds": np.array([v[2] for v in counts], dtype=np.float64),
            }
        )
        return ClassTables(
            type="+".join(self.key),
            key=list(self.key),
            classes=classes,
            observed=self.codes,
            df_c=df_c,
            entries=_entries(tables.starts, self.codes),
        )


def growing_classes(keys: Sequence[Sequence[str]]) -> list[GrowingClasses]:
    """Nothing yet of the class tables of each of ``keys``."""
    return [GrowingClasses(tuple(key)) for key in keys]


def _changed(held: np.ndarray | None, gone: list[float], new: list[float]) -> np.ndarray:
    """``held`` (sorted) without the seconds ``gone`` (one each) and with ``new``, sorted."""
    now = np.sort(np.concatenate([held if held is not None else [], new]).astype(np.float64))
    for s in gone:
        now = np.delete(now, int(np.searchsorted(now, s)))
    return now


def _pair_values(seconds: np.ndarray) -> tuple[int, float, float]:
    """A pair's count, mean and median (halfway between the middle two) of sorted seconds,
    summed as :func:`~robotale.ekg.tables.class_tables` sums them."""
    count = len(seconds)
    mean = float(np.add.reduceat(seconds, [0])[0]) / count
    median = float((seconds[(count - 1) // 2] + seconds[count // 2]) / 2)
    return count, mean, median
