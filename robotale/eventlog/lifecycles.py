"""How tags say when an activity ends: the lifecycle of each tag, from its field or from the
mode the preparation was given."""

from __future__ import annotations

import warnings
from pathlib import Path

import pandas as pd

from robotale.errors import InputError
from robotale.eventlog import schema
from robotale.eventlog.enrich import PreparationWarning

_LIFECYCLES = {schema.START, schema.NONE, *schema.ENDINGS}


#: how tags say when an activity ends: their lifecycle field (``explicit``), the robot's next
#: tag (``implicit``), or not at all: each tag one event (``events``)
LIFECYCLE_MODES = ("explicit", "implicit", "events")


def lifecycles(rows: pd.DataFrame, topic: str, run: Path, mode: str | None) -> pd.Series:
    """The tags' lifecycles: their field's, or ``complete`` for tags that are single events."""
    if schema.LIFECYCLE not in rows or mode == "events":
        if mode == "implicit":
            return pd.Series(schema.START, index=rows.index, dtype=object)
        if mode is None:
            warnings.warn(
                f"{run}: the tags on {topic} have no lifecycle, so each is a single event; "
                "--lifecycle implicit makes each an activity that the robot's next tag ends.",
                PreparationWarning,
                stacklevel=5,
            )
        return pd.Series(schema.COMPLETE, index=rows.index, dtype=object)
    given = rows[schema.LIFECYCLE].astype(str)
    lifecycles = given.str.strip().str.lower().replace("", schema.NONE)
    bad = ~lifecycles.isin(_LIFECYCLES)
    if bad.any():
        at = rows.loc[bad, schema.TIMESTAMP].iloc[0].isoformat()
        raise InputError(
            f"{run}: a tag on {topic} at {at} has lifecycle {given[bad].iloc[0]!r}; "
            "expected start, complete or none (or an outcome: aborted, cancelled, ate_abort)."
        )
    return lifecycles
