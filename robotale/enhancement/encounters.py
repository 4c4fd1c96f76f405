"""Where robots were at the same place at the same moment, and where their regions overlap.

Two robots *meet* when, in one run, a position of one and the other's position nearest in
time are at most :data:`SECONDS` apart in time and at most :data:`METRES` apart in space,
measured in 3D (``z`` is 0 where the log has none): a drone flying 5 m above a ground robot
is 5 m away from it. Consecutive positions of the first robot that meet the other are one
*encounter*, with its first and last moment, its closest distance and where it happened.

A robot's *region* in a run is the box its positions span in x, y and z; two robots' regions
overlap in a run when their boxes intersect on all three axes. Regions say where robots
worked, not that they met: two robots can cross the same box hours apart.
"""

from __future__ import annotations

from typing import Any

import numpy as np
import pandas as pd

from robotale.eventlog.schema import CASE, ROBOT, TIMESTAMP, X, Y, Z

#: robots at most this far apart (metres, in 3D) are at the same place
METRES = 2.0
#: positions at most this far apart in time (seconds) are at the same moment
SECONDS = 1.0
AXES = (X, Y, Z)


def positions(log: pd.DataFrame) -> pd.DataFrame:
    """The rows with a position: case, robot, time and x, y, z (z 0 where missing)."""
    if X not in log.columns or Y not in log.columns or ROBOT not in log.columns:
        return pd.DataFrame(columns=[CASE, ROBOT, TIMESTAMP, *AXES])
    columns = [c for c in (CASE, ROBOT, TIMESTAMP, X, Y, Z) if c in log.columns]
    placed = log[columns].dropna(subset=[ROBOT, X, Y])
    placed = placed.assign(
        **{
            Z: placed[Z].fillna(0.0) if Z in placed.columns else 0.0,
            CASE: placed[CASE].astype(str) if CASE in placed.columns else "",
            ROBOT: placed[ROBOT].astype(str),
        }
    )
    return placed.astype({X: float, Y: float, Z: float})


def encounters(
    placed: pd.DataFrame, metres: float = METRES, seconds: float = SECONDS
) -> pd.DataFrame:
    """One row per encounter of two robots (see the module): robots, case, start, end,
    closest distance and the first robot's place then."""
    columns = ["robot", "other", CASE, "start", "end", "closest", *AXES]
    rows = []
    robots = sorted(placed[ROBOT].unique()) if not placed.empty else []
    by_robot = {name: mine.sort_values(TIMESTAMP, kind="stable") for name, mine in
                placed.groupby(ROBOT, sort=True)}  # fmt: skip
    for i, first in enumerate(robots):
        for second in robots[i + 1 :]:
            rows.append(_pair(by_robot[first], by_robot[second], metres, seconds))
    found = [r for r in rows if not r.empty]
    if not found:
        return pd.DataFrame(columns=columns)
    return pd.concat(found, ignore_index=True)[columns]


def _pair(mine: pd.DataFrame, theirs: pd.DataFrame, metres: float, seconds: float):
    right = theirs[[CASE, TIMESTAMP, *AXES]].rename(columns={a: f"_{a}" for a in AXES})
    right = right.assign(_at=right[TIMESTAMP])
    near = pd.merge_asof(
        mine[[CASE, ROBOT, TIMESTAMP, *AXES]],
        right,
        on=TIMESTAMP,
        by=CASE,
        tolerance=pd.Timedelta(seconds=seconds),
        direction="nearest",
    )
    gaps = np.stack([near[a].to_numpy() - near[f"_{a}"].to_numpy() for a in AXES])
    distance = np.sqrt((gaps**2).sum(axis=0))
    met = np.nan_to_num(distance, nan=np.inf) <= metres
    if not met.any():
        return pd.DataFrame()
    near = near.assign(_distance=distance)
    # a new encounter wherever a meeting position follows one that did not meet (or a new run)
    cases = near[CASE].to_numpy(object)
    new_run = np.r_[True, cases[1:] != cases[:-1]]
    begins = met & (new_run | ~np.r_[False, met[:-1]])
    episode = np.cumsum(begins)
    meeting = near[met].assign(_episode=episode[met])
    grouped = meeting.groupby("_episode", sort=True)
    table = grouped.agg(
        **{CASE: (CASE, "first"), "start": (TIMESTAMP, "min"), "end": (TIMESTAMP, "max")},
        closest=("_distance", "min"),
    )
    closest = meeting.loc[grouped["_distance"].idxmin(), list(AXES)].to_numpy()
    table[list(AXES)] = closest
    return table.reset_index(drop=True).assign(
        robot=str(mine[ROBOT].iloc[0]), other=str(theirs[ROBOT].iloc[0])
    )


def run_regions(placed: pd.DataFrame) -> pd.DataFrame:
    """Per run and robot, the box its positions span: x, y and z min and max."""
    if placed.empty:
        return pd.DataFrame(columns=[CASE, ROBOT])
    boxes = placed.groupby([CASE, ROBOT], sort=True)[list(AXES)].agg(["min", "max"])
    boxes.columns = [f"{axis}_{end}" for axis, end in boxes.columns]
    return boxes.reset_index()


def region_overlaps(regions: pd.DataFrame) -> list[dict[str, Any]]:
    """Per run, every pair of robots whose boxes intersect on x, y and z, with the shared
    box."""
    found = []
    for case, boxes in regions.groupby(CASE, sort=True):
        rows = boxes.sort_values(ROBOT).to_dict("records")
        for i, first in enumerate(rows):
            for second in rows[i + 1 :]:
                shared = {
                    axis: [
                        max(first[f"{axis}_min"], second[f"{axis}_min"]),
                        min(first[f"{axis}_max"], second[f"{axis}_max"]),
                    ]
                    for axis in AXES
                }
                if all(low <= high for low, high in shared.values()):
                    found.append(
                        {"case": str(case), "robots": [first[ROBOT], second[ROBOT]], **shared}
                    )
    return found
