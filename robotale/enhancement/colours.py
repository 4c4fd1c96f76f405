"""The one owner of which colour an activity is drawn in.

Every figure that colours activities (the Timeline's bars, the spatial scatter) asks here, so
an activity has the same colour on every page and in every run of a log: colours go to the
log's activities in name order, so two activities of a log share a colour only when it has
more than :data:`PALETTE` holds (32, beyond which they repeat).
"""

from __future__ import annotations

from collections.abc import Iterable

import pandas as pd

from robotale.eventlog.schema import ACTIVITY

#: 32 colours far apart from each other (Kelly's colours of maximum contrast without white and
#: black, then Tableau's ten and two more), none the red of a lost message
PALETTE = (
    "#f3c300",
    "#875692",
    "#f38400",
    "#a1caf1",
    "#be0032",
    "#c2b280",
    "#848482",
    "#008856",
    "#e68fac",
    "#0067a5",
    "#f99379",
    "#604e97",
    "#f6a600",
    "#b3446c",
    "#dcd300",
    "#882d17",
    "#8db600",
    "#654522",
    "#e25822",
    "#2b3d26",
    "#4e79a7",
    "#f28e2b",
    "#e15759",
    "#76b7b2",
    "#59a14f",
    "#edc948",
    "#b07aa1",
    "#ff9da7",
    "#9c755f",
    "#bab0ac",
    "#1f77b4",
    "#17becf",
)


def activity_colours(activities: Iterable[object]) -> dict[str, str]:
    """Activity name -> colour, for the activities of a log (names in text order)."""
    names = sorted({str(a) for a in activities if not pd.isna(a)})
    return {name: PALETTE[i % len(PALETTE)] for i, name in enumerate(names)}


def log_colours(log: pd.DataFrame) -> dict[str, str]:
    """:func:`activity_colours` of every activity of ``log``."""
    if ACTIVITY not in log.columns:
        return {}
    return activity_colours(pd.unique(log[ACTIVITY].astype(object)))
