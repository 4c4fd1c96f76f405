"""The class tables grown update by update (:class:`GrowingClasses`) are, table for table,
:func:`class_tables` of the whole log, over random splits of a recorded run grown as the
monitor grows it (only the tail made again, :class:`LiveEvents`)."""

from __future__ import annotations

import random

import numpy as np
import pandas as pd
import pytest
from live_logs import recorded_tags

from robotale.ekg.classgrowth import growing_classes
from robotale.ekg.keys import built_keys, default_entities
from robotale.ekg.tables import class_tables, graph_tables, utc_ticks
from robotale.results.live import LiveEvents


def kept_rows(events: pd.DataFrame, before: pd.DataFrame | None, same: int) -> int:
    """``same``, or 0 where the first rows could not be kept (the update's own rule, written
    again here): other column types, or a later event older than one of them."""
    if before is None or same <= 0 or not events.dtypes.equals(before.dtypes):
        return 0
    ticks = utc_ticks(events)
    return same if same == len(events) or ticks[same:].min() >= ticks[:same].max() else 0


def by_pair(df_c: pd.DataFrame) -> pd.DataFrame:
    return df_c.sort_values(["source", "target", "entityType"]).reset_index(drop=True)


@pytest.mark.parametrize("seed", [1, 2, 3])
def test_grown_class_tables_are_those_of_the_whole_log_after_random_splits(seed):
    tags, draw = recorded_tags(90, seed), random.Random(seed)
    cuts = [*sorted(draw.sample(range(1, len(tags)), 12)), len(tags)]
    made, before, grown, held = LiveEvents(), None, None, 0
    for cut in cuts:
        log, _, _, same = made.add("run", tags[len(made.tags) : cut])
        types = default_entities(log.columns)
        keys = [key.split(",") for key in built_keys(types)]
        tables = graph_tables(log, types)
        same = kept_rows(tables.events, before, same)
        grown = [
            kept.grown(tables, same)
            for kept in ([g for g, _ in grown] if grown else growing_classes(keys))
        ]
        for (kept, incremental), key in zip(grown, keys, strict=True):
            whole = class_tables(tables, key)
            pd.testing.assert_frame_equal(incremental.classes, whole.classes)
            np.testing.assert_array_equal(incremental.observed, whole.observed)
            pd.testing.assert_frame_equal(by_pair(incremental.df_c), by_pair(whole.df_c))
            pd.testing.assert_frame_equal(incremental.entries, whole.entries)
            held += int(np.searchsorted(kept.last, same)) if same else 0
        before = tables.events
    assert held > 0  # some updates kept edges of the first events
