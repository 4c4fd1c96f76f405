"""What a live run must be once it has ended: the events ``prepare`` makes of its recording."""

from __future__ import annotations

import random
from pathlib import Path

import pandas as pd

from robotale.fame_runtime.tags import Tag

#: a recorded run: the thesis' agricultural mission (drone and tractors, their messages)
RECORDING = Path(__file__).resolve().parents[1] / "examples" / "thesis" / "robotic_data.csv"

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


def recorded_tags(count: int, seed: int) -> list[Tag]:
    """The first ``count`` tags of the recording in the order a monitor might hear them:
    the recording's order, with some neighbours of different robots swapped (a robot's tag
    heard after a later one of another robot: a late tag)."""
    rows = pd.read_csv(RECORDING, nrows=count, dtype=str, keep_default_na=False)
    times = pd.to_datetime(rows["time"], utc=True, format="ISO8601")
    stamps = (times - pd.Timestamp(0, tz="UTC")).dt.total_seconds()
    tags = [
        Tag(float(stamp), row.resource, row.activity, row.lifecycle, row.msg_id, row.msg_role,
            row.msg_payload)
        for stamp, row in zip(stamps, rows.itertuples(index=False), strict=True)
    ]  # fmt: skip
    draw = random.Random(seed)
    for i in draw.sample(range(count - 1), count // 10):
        if tags[i].robot != tags[i + 1].robot:
            tags[i], tags[i + 1] = tags[i + 1], tags[i]
    return tags
