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
    # the run and robot columns keep their own values: turned into text once per distinct
    # value where a name is written, not once per position
    placed = placed.assign(
        **{Z: placed[Z].fillna(0.0) if Z in placed.columns else 0.0}
        | ({} if CASE in placed.columns else {CASE: ""})
    )
    return placed.astype({X: float, Y: float, Z: float})


def encounters(
    placed: pd.DataFrame, metres: float = METRES, seconds: float = SECONDS
) -> pd.DataFrame:
    """One row per encounter of two robots (see the module): robots, case, start, end,
    closest distance and the first robot's place then."""
    columns = ["robot", "other", CASE, "start", "end", "closest", *AXES]
    if placed.empty:
        return pd.DataFrame(columns=columns)
    # one sort of all positions by robot, run and time; each robot's rows then a slice
    keys = _run_time_keys(placed, seconds)
    robot_code, names = pd.factorize(placed[ROBOT], sort=True)
    order = np.lexsort((keys, robot_code))
    bounds = np.searchsorted(robot_code[order], np.arange(len(names) + 1))
    xyz = placed[list(AXES)].to_numpy(float)[order]
    key = keys[order]
    # the columns an encounter reports, read once (a copy of the rows per pair cost more)
    runs = pd.factorize(placed[CASE])[0]
    if (runs < 0).any():  # a position without a run: its run compared as the value is
        runs = placed[CASE].to_numpy(object)
    read = {
        CASE: placed[CASE].array,
        TIMESTAMP: placed[TIMESTAMP].array,  # the column's own type: zone-aware times stay so
        "runs": runs[order],
        "xyz": xyz,
    }
    found = []
    for i in range(len(names)):
        for j in range(i + 1, len(names)):
            mine, theirs = slice(bounds[i], bounds[i + 1]), slice(bounds[j], bounds[j + 1])
            met, distance = _meet(key[mine], xyz[mine], key[theirs], xyz[theirs], metres, seconds)
            if met.any():
                rows = {"order": order[mine], "runs": read["runs"][mine],
                        "xyz": read["xyz"][mine], CASE: read[CASE],
                        TIMESTAMP: read[TIMESTAMP]}  # fmt: skip
                found.append(_episodes(rows, met, distance, str(names[i]), str(names[j])))
    if not found:
        return pd.DataFrame(columns=columns)
    return pd.concat(found, ignore_index=True)[columns]


def _meet(mine_key, mine_xyz, theirs_key, theirs_xyz, metres: float, seconds: float):
    """For each position of the first robot, whether the second's position nearest in time
    in the same run (at most ``seconds`` away) is within ``metres`` in 3D, and how far."""
    after = np.clip(np.searchsorted(theirs_key, mine_key), 0, len(theirs_key) - 1)
    before = np.clip(after - 1, 0, len(theirs_key) - 1)
    nearer = np.abs(theirs_key[before] - mine_key) <= np.abs(theirs_key[after] - mine_key)
    nearest = np.where(nearer, before, after)
    close_in_time = np.abs(theirs_key[nearest] - mine_key) <= int(seconds * 1e9)
    distance = np.sqrt(((mine_xyz - theirs_xyz[nearest]) ** 2).sum(axis=1))
    return close_in_time & (distance <= metres), distance


def _episodes(rows: dict, met: np.ndarray, distance: np.ndarray, robot: str, other: str):
    """Consecutive meeting positions of ``robot`` (in run and time order) as encounters;
    ``rows``: its positions' rows in the placed table (``order``), their runs and x, y, z in
    that order (``runs``, ``xyz``), and the placed table's case and time columns."""
    # a new encounter wherever a meeting position follows one that did not meet (or a new run)
    cases = rows["runs"]
    new_run = np.r_[True, cases[1:] != cases[:-1]]
    begins = met & (new_run | ~np.r_[False, met[:-1]])
    # each encounter is a contiguous stretch of the meeting positions, in time order within
    # one run: its first and last rows are its start and end, reduced with numpy at once
    # (a groupby per pair of robots costs more than the positions it groups)
    meeting = np.flatnonzero(met)
    first = np.flatnonzero(begins[meeting])
    last = np.r_[first[1:], len(meeting)] - 1
    near = distance[meeting]
    closest = np.minimum.reduceat(near, first)
    episode = np.cumsum(begins[meeting]) - 1
    # the first position of each encounter at its closest distance, as idxmin picks it
    at_closest = np.flatnonzero(near == closest[episode])
    _, chosen = np.unique(episode[at_closest], return_index=True)
    where = meeting[at_closest[chosen]]
    order, times, xyz = rows["order"], rows[TIMESTAMP], rows["xyz"][where]
    return pd.DataFrame(
        {
            CASE: rows[CASE][order[meeting[first]]],
            "start": times[order[meeting[first]]],
            "end": times[order[meeting[last]]],
            "closest": closest,
            **{axis: xyz[:, i] for i, axis in enumerate(AXES)},
            "robot": robot,
            "other": other,
        }
    )


def _run_time_keys(placed: pd.DataFrame, seconds: float) -> np.ndarray:
    """One integer per position that orders by run, then time: the run's number times the
    longest run (plus twice ``seconds``) plus nanoseconds since the run's first position, so
    no two positions of different runs are ever ``seconds`` apart."""
    if placed.empty:
        return np.zeros(0, dtype=np.int64)
    ticks = np.asarray(pd.to_datetime(placed[TIMESTAMP], utc=True).array.as_unit("ns").asi8)
    run = pd.factorize(placed[CASE], sort=True)[0]
    first = pd.Series(ticks).groupby(run).transform("min").to_numpy()
    since = ticks - first
    span = int(since.max()) + 2 * int(seconds * 1e9) + 1
    return run.astype(np.int64) * span + since


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
    if regions.empty:
        return []
    pairs = regions.merge(regions, on=CASE, suffixes=("", "_other"))
    pairs = pairs[pairs[ROBOT].astype(str) < pairs[f"{ROBOT}_other"].astype(str)]
    shared = {}
    overlap = pd.Series(True, index=pairs.index)
    for axis in AXES:
        low = np.maximum(pairs[f"{axis}_min"], pairs[f"{axis}_min_other"])
        high = np.minimum(pairs[f"{axis}_max"], pairs[f"{axis}_max_other"])
        shared[axis] = (low, high)
        overlap &= low <= high
    pairs = pairs[overlap].sort_values([CASE, ROBOT, f"{ROBOT}_other"], kind="stable")
    # whole columns to Python values at once: a row at a time costs a Series per pair
    at = pairs.index
    ends = {
        axis: zip(
            shared[axis][0].loc[at].to_numpy(float).tolist(),
            shared[axis][1].loc[at].to_numpy(float).tolist(),
            strict=True,
        )
        for axis in AXES
    }
    columns = zip(
        pairs[CASE].tolist(),
        pairs[ROBOT].tolist(),
        pairs[f"{ROBOT}_other"].tolist(),
        *ends.values(),
        strict=True,
    )
    return [
        {
            "case": str(case),
            "robots": [str(robot), str(other)],
            **{axis: list(span) for axis, span in zip(AXES, spans, strict=True)},
        }
        for case, robot, other, *spans in columns
    ]
