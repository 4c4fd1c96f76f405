"""What every perspective returns: tables, plotly figures, a summary, or why there is no data."""

from __future__ import annotations

import json
from collections.abc import Callable, Iterator, Mapping
from dataclasses import dataclass, field
from typing import Any

import pandas as pd

from robotale.discovery.graph import json_ready
from robotale.eventlog.schema import ACTIVITY, CSV_NAMES, ROBOT


@dataclass(slots=True)
class Perspective:
    """One perspective of a log (or of one activity / class of it, for a drill-down).

    ``tables`` are pandas DataFrames (the first is the main one) whose log columns carry their
    short names (``case``, ``activity``, ``time`` ...), ``figures`` plotly figures (a
    :class:`Figures` draws each when it is first read), ``summary`` a
    few headline figures. ``message`` says why a perspective has no data (a log
    without positions, say); then tables and figures are empty.
    """

    name: str
    tables: dict[str, pd.DataFrame] = field(default_factory=dict)
    figures: Mapping[str, Any] = field(default_factory=dict)
    summary: dict[str, Any] = field(default_factory=dict)
    message: str | None = None

    def __post_init__(self) -> None:
        self.tables = {name: t.rename(columns=CSV_NAMES) for name, t in self.tables.items()}

    @property
    def has_data(self) -> bool:
        return self.message is None

    @property
    def table(self) -> pd.DataFrame:
        """The main table."""
        return next(iter(self.tables.values())) if self.tables else pd.DataFrame()

    @property
    def figure(self):
        """The main figure (``None`` without data)."""
        return next(iter(self.figures.values()), None)

    def to_dict(self) -> dict[str, Any]:
        """Plain JSON-serialisable data: tables as lists of records, figures as plotly JSON."""
        return {
            "name": self.name,
            "message": self.message,
            "summary": json_ready(self.summary),
            "tables": {name: table_records(t) for name, t in self.tables.items()},
            "figures": {name: json.loads(f.to_json()) for name, f in self.figures.items()},
        }


class Figures(Mapping[str, Any]):
    """Figures by name, each drawn by its function the first time it is read: a caller that
    wants the numbers only (the findings, a benchmark) never pays for drawing, which on a
    large log takes longer than the numbers."""

    def __init__(self, drawers: dict[str, Callable[[], Any]]) -> None:
        self._drawers = drawers
        self._drawn: dict[str, Any] = {}

    def __getitem__(self, name: str) -> Any:
        if name not in self._drawn:
            self._drawn[name] = self._drawers[name]()
        return self._drawn[name]

    def __iter__(self) -> Iterator[str]:
        return iter(self._drawers)

    def __len__(self) -> int:
        return len(self._drawers)


def no_data(name: str, message: str) -> Perspective:
    return Perspective(name=name, message=message)


def focus_events(log: pd.DataFrame, activity: str | None, robot: str | None) -> pd.DataFrame:
    """The events of one activity and/or one robot (a class of the activity+robot model)."""
    keep = pd.Series(True, index=log.index)
    if activity is not None:
        keep &= log[ACTIVITY].astype("string").eq(activity).fillna(False)
    if robot is not None and ROBOT in log.columns:
        keep &= log[ROBOT].astype("string").eq(robot).fillna(False)
    return log[keep.to_numpy(bool)]


def focus_label(activity: str | None, robot: str | None) -> str:
    parts = [f"activity {activity}" if activity else "", f"robot {robot}" if robot else ""]
    return " and ".join(p for p in parts if p) or "the log"


def table_records(table: pd.DataFrame) -> list[dict[str, Any]]:
    return [json_ready(row) for row in table.to_dict(orient="records")]
