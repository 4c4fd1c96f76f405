"""What a live run must be once it has ended: the events ``prepare`` makes of its recording."""

from __future__ import annotations

import pandas as pd

#: the columns a live log and a prepared recording share row by row
SHARED = ["robot", "concept:name", "lifecycle:transition", "lifecycle:state"]
SHARED += ["msg_id", "msg_role", "msg_payload", "source_topic", "source_index"]


def assert_prepared(events: pd.DataFrame, prepared: pd.DataFrame) -> None:
    """``events`` (a live run's) are, row by row, ``prepared`` (its recording's): robot,
    activity, lifecycle, message, source, order, and time within a microsecond (the stamps are
    floats in Neo4j, integer nanoseconds in a bag)."""
    assert len(events) == len(prepared) > 20
    live_rows = events[SHARED].astype(object).fillna("").to_numpy().tolist()
    assert live_rows == prepared[SHARED].astype(object).fillna("").to_numpy().tolist()
    lag = (events["time:timestamp"] - prepared["time:timestamp"]).abs().max()
    assert lag <= pd.Timedelta(microseconds=1), lag
