"""Spatial occupancy: where the robots were while doing each activity (thesis 6.2.2, fig. 7.8).

The main table gives, per activity and robot, how many positions were recorded and their
bounds; the figure is the 3D scatter of all positions, coloured by activity, one symbol per
robot; the ``encounters`` table says when two robots were at the same place at the same moment
(:mod:`robotale.enhancement.encounters`). Given a field (x and y bounds), the covered
fraction says how much of it the robots passed over: the field is cut into square cells and a
cell counts as covered when a robot's path crosses it. Between two recorded positions a robot
is taken to move in a straight line, since positions are sampled while it moves continuously.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pandas as pd
import plotly.graph_objects as go

from robotale.enhancement.colours import log_colours
from robotale.enhancement.context import LogAnalysis, analysis_of
from robotale.enhancement.encounters import encounters, positions
from robotale.enhancement.result import (
    Figures,
    Perspective,
    focus_events,
    focus_label,
    no_data,
)
from robotale.errors import InputError
from robotale.eventlog.schema import ACTIVITY, CASE, ROBOT, TIMESTAMP, X, Y, Z

#: the 3D scatter draws at most this many positions (a random sample beyond that): a browser
#: stays responsive, and the tables and coverage always use every position
SCATTER_POINTS = 20_000


@dataclass(frozen=True, slots=True)
class Field:
    """A rectangular field on the ground, cut into ``cell``-sized squares."""

    x_min: float
    x_max: float
    y_min: float
    y_max: float
    cell: float = 1.0

    def __post_init__(self) -> None:
        if not (self.x_max > self.x_min and self.y_max > self.y_min and self.cell > 0):
            raise InputError(
                f"the field {self.x_min},{self.x_max},{self.y_min},{self.y_max} with cell "
                f"{self.cell} is empty; give x_min,x_max,y_min,y_max with min < max and cell > 0."
            )

    @classmethod
    def parse(cls, text: str) -> Field:
        """``"x_min,x_max,y_min,y_max[,cell]"`` (for instance ``0,10,0,10``)."""
        try:
            numbers = [float(part) for part in text.split(",")]
        except ValueError:
            numbers = []
        if len(numbers) not in (4, 5):
            raise InputError(f"the field {text!r} is not x_min,x_max,y_min,y_max[,cell].")
        return cls(*numbers)

    @property
    def shape(self) -> tuple[int, int]:
        return (
            int(np.ceil((self.x_max - self.x_min) / self.cell - 1e-9)),
            int(np.ceil((self.y_max - self.y_min) / self.cell - 1e-9)),
        )


def spatial_perspective(
    log: pd.DataFrame | LogAnalysis,
    *,
    activity: str | None = None,
    robot: str | None = None,
    field: Field | None = None,
) -> Perspective:
    """Positions per activity and robot, their bounds, a 3D scatter and the covered field."""
    log = analysis_of(log).log
    if X not in log.columns or Y not in log.columns:
        return no_data("spatial", "the log has no positions (no x and y columns).")
    events = focus_events(log, activity, robot)
    placed = events.dropna(subset=[X, Y])
    if placed.empty:
        return no_data("spatial", f"no event of {focus_label(activity, robot)} has a position.")
    placed = placed.assign(**{Z: placed[Z] if Z in placed.columns else 0.0})
    shown = (
        placed.sample(SCATTER_POINTS, random_state=0) if len(placed) > SCATTER_POINTS else placed
    )
    result = Perspective(
        name="spatial",
        tables={
            "occupancy": _occupancy(placed),
            # the same place at the same moment (in 3D and time), of the focused events
            "encounters": encounters(positions(placed)),
        },
        figures=Figures({"scatter": lambda: _scatter(shown.sort_index(), log_colours(log))}),
        summary={"positions": len(placed), "plotted": len(shown), "bounds": bounds(placed)},
    )
    if field is not None:
        coverage = covered_cells(placed, field)
        result.tables["coverage"] = _coverage_table(placed, field)
        result.summary["field"] = {
            "x": [field.x_min, field.x_max],
            "y": [field.y_min, field.y_max],
            "cell": field.cell,
            "cells": int(coverage.size),
            "covered_fraction": float(coverage.mean()),
        }
    return result


def bounds(positions: pd.DataFrame) -> dict[str, list[float]]:
    """``{"x": [min, max], "y": [...], "z": [...]}`` of the positions."""
    return {
        axis: [float(positions[axis].min()), float(positions[axis].max())]
        for axis in (X, Y, Z)
        if positions[axis].notna().any()
    }


def covered_cells(positions: pd.DataFrame, field: Field) -> np.ndarray:
    """A boolean grid (x cells by y cells): which cells of the field a robot's path crossed."""
    grid = np.zeros(field.shape, dtype=bool)
    for _, path in _paths(positions):
        xs, ys = _sample_path(path[X].to_numpy(float), path[Y].to_numpy(float), field.cell / 4)
        ix = np.floor((xs - field.x_min) / field.cell).astype(int)
        iy = np.floor((ys - field.y_min) / field.cell).astype(int)
        inside = (ix >= 0) & (ix < grid.shape[0]) & (iy >= 0) & (iy < grid.shape[1])
        grid[ix[inside], iy[inside]] = True
    return grid


def _paths(positions: pd.DataFrame):
    keys = [k for k in (CASE, ROBOT) if k in positions.columns]
    ordered = positions.sort_values(TIMESTAMP, kind="stable")
    if not keys:
        yield None, ordered
        return
    yield from ordered.groupby(keys, dropna=False, sort=False)


def _sample_path(xs: np.ndarray, ys: np.ndarray, step: float) -> tuple[np.ndarray, np.ndarray]:
    """Points every ``step`` along the straight segments between consecutive positions."""
    if len(xs) < 2:
        return xs, ys
    lengths = np.hypot(np.diff(xs), np.diff(ys))
    samples = np.maximum(1, np.ceil(lengths / step).astype(int))
    fractions = np.concatenate([np.arange(n) / n for n in samples])
    starts = np.repeat(np.arange(len(lengths)), samples)
    sampled_x = xs[starts] + fractions * np.diff(xs)[starts]
    sampled_y = ys[starts] + fractions * np.diff(ys)[starts]
    return np.append(sampled_x, xs[-1]), np.append(sampled_y, ys[-1])


def _occupancy(placed: pd.DataFrame) -> pd.DataFrame:
    keys = [ACTIVITY] + ([ROBOT] if ROBOT in placed.columns else [])
    grouped = placed.groupby(keys, dropna=False, sort=True)
    table = grouped.agg(
        positions=(X, "size"),
        x_min=(X, "min"),
        x_max=(X, "max"),
        y_min=(Y, "min"),
        y_max=(Y, "max"),
        z_min=(Z, "min"),
        z_max=(Z, "max"),
        x_mean=(X, "mean"),
        y_mean=(Y, "mean"),
        z_mean=(Z, "mean"),
    )
    return table.reset_index().rename(columns={ACTIVITY: "activity"})


def _coverage_table(placed: pd.DataFrame, field: Field) -> pd.DataFrame:
    rows = []
    robots = placed[ROBOT].dropna().unique() if ROBOT in placed.columns else [None]
    for name in sorted(robots, key=str):
        mine = placed if name is None else placed[placed[ROBOT] == name]
        inside = mine[X].between(field.x_min, field.x_max) & mine[Y].between(
            field.y_min, field.y_max
        )
        rows.append(
            {
                "robot": name,
                "covered_fraction": float(covered_cells(mine, field).mean()),
                "positions_inside": int(inside.sum()),
                "positions_outside": int((~inside).sum()),
            }
        )
    return pd.DataFrame(rows)


#: the marker symbols a 3D scatter offers, one per robot
SYMBOLS = (
    "circle",
    "diamond",
    "square",
    "cross",
    "x",
    "circle-open",
    "diamond-open",
    "square-open",
)


def _scatter(placed: pd.DataFrame, colours: dict[str, str]):
    """One trace per activity (its colour, the log's: the same on every page), one marker
    symbol per robot."""
    robots = placed[ROBOT].astype("string").fillna("") if ROBOT in placed.columns else None
    names = sorted(set(robots)) if robots is not None else []
    symbol_of = {r: SYMBOLS[i % len(SYMBOLS)] for i, r in enumerate(names)}
    figure = go.Figure()
    for activity, points in placed.groupby(ACTIVITY, sort=True):
        who = robots.loc[points.index] if robots is not None else None
        figure.add_scatter3d(
            x=points[X],
            y=points[Y],
            z=points[Z],
            mode="markers",
            name=str(activity),
            # fixed-width text arrays: plotly copies them whole, not string by string
            marker={
                "size": 3,
                "color": colours.get(str(activity)),
                "symbol": None if who is None else who.map(symbol_of).to_numpy(str),
            },
            text=None if who is None else who.to_numpy(str),
            hovertemplate="%{text}<br>x %{x:.2f}, y %{y:.2f}, z %{z:.2f}",
        )
    figure.update_layout(
        title="Spatial occupancy by activity (colour) and robot (symbol)",
        scene={"xaxis_title": "x", "yaxis_title": "y", "zaxis_title": "z"},
    )
    return figure
