"""A live run's positions grown look by look equal the table made afresh of every sample
heard so far, however the samples were split into the batches the looks found (some late,
some at one time): the reader writes the new samples past the ones held rather than make the
table again at every look, and that must change no answer."""

from __future__ import annotations

import random

import numpy as np
import pandas as pd
import pytest

from robotale.ekg.live import Pose
from robotale.enhancement import mission_state
from robotale.enhancement.mission_state import Tracks
from robotale.results.live import Positions

ROBOTS = ("rover_2", "rover_1", "rover_3")
START = pd.Timestamp(1_700_000_000, unit="s", tz="UTC")


def heard(seed: int) -> list[list[Pose]]:
    """Batches of 1 to 12 odometry samples of three robots at 10 Hz, two of them at the
    same times, now and then a batch heard late (older than the last one held)."""
    draw, samples = random.Random(seed), []
    for tick in range(120):
        for robot in ROBOTS:
            # rover_3 a little apart, rover_1 and rover_2 at one time
            stamp = START.timestamp() + tick / 10 + (0.003 if robot == "rover_3" else 0.0)
            samples.append(Pose(stamp, robot, draw.uniform(-5, 5), draw.uniform(-5, 5), 0.0))
    batches, first = [], 0
    while first < len(samples):
        size = draw.randint(1, 12)
        batches.append(samples[first : first + size])
        first += size
    for _ in range(3):  # late ones: a batch swapped with the one before it
        at = draw.randrange(1, len(batches))
        batches[at - 1], batches[at] = batches[at], batches[at - 1]
    return batches


def afresh(poses: list[Pose]) -> pd.DataFrame:
    """The positions table of ``poses`` made whole, as pandas sorts it."""
    table = pd.DataFrame(
        {
            "robot": pd.Series([p.robot for p in poses], dtype=object),
            "s": np.array([p.stamp for p in poses], dtype=float) - START.timestamp(),
            "x": [p.x for p in poses],
            "y": [p.y for p in poses],
            "z": [p.z for p in poses],
        }
    )
    return table.sort_values(["s", "robot"], kind="stable").reset_index(drop=True)


@pytest.mark.parametrize("seed", [1, 2, 3])
def test_positions_grown_batch_by_batch_equal_the_table_made_of_all_samples(monkeypatch, seed):
    """After each batch, the table and the tracks equal those made afresh of every sample
    heard (the tracks' samples in any window); most batches were written past the samples
    held (the table made again whole only for a late batch)."""
    whole: list[int] = []  # the sizes the tracks were made again whole at
    of = Tracks.of.__func__  # type: ignore[attr-defined]

    def counted(cls: type[Tracks], table: pd.DataFrame) -> Tracks:
        whole.append(len(table))
        return of(cls, table)

    monkeypatch.setattr(mission_state.Tracks, "of", classmethod(counted))
    positions, seen = Positions(), []
    batches = heard(seed)
    for batch in batches:
        positions.add(batch)
        seen += batch
        table, tracks = positions.since(START)
        expected = afresh(seen)
        pd.testing.assert_frame_equal(table, expected)
        fresh = Tracks.of(expected)
        whole.pop()  # the reference's own, not the reader's
        for window in ((-1.0, 100.0), (2.0, 5.05), (7.3, 7.3)):
            assert tracks.between(*window) == fresh.between(*window), window
    assert len(whole) < len(batches) / 2, whole


def arriving(seed: int) -> list[list[Pose]]:
    """Batches as the monitor stores the samples of three robots published from different
    processes: each robot's samples in its own order, but they arrive up to a quarter of a
    second late, so a batch may hold one robot's sample later than another's in the next."""
    draw, samples, last = random.Random(seed), [], dict.fromkeys(ROBOTS, 0.0)
    for tick in range(120):
        for robot in ROBOTS:
            stamp = START.timestamp() + tick / 10 + (0.003 if robot == "rover_3" else 0.0)
            last[robot] = max(last[robot], stamp + draw.uniform(0.0, 0.25))
            samples.append((last[robot], Pose(stamp, robot, draw.uniform(-5, 5), 0.0, 0.0)))
    samples.sort(key=lambda arrived: arrived[0])
    batches, first = [], 0
    while first < len(samples):
        size = draw.randint(1, 8)
        batches.append([pose for _, pose in samples[first : first + size]])
        first += size
    return batches


@pytest.mark.parametrize("seed", [4, 5])
def test_positions_of_robots_out_of_step_are_merged_not_made_again(monkeypatch, seed):
    """Samples of different robots out of time order (each robot's in order): after each
    batch the table and tracks equal those made afresh, the table is never made again whole
    (the batch is merged into the rows from its first time on), and a table handed out
    earlier still shows what it showed (a run made then holds it)."""
    whole: list[int] = []
    of = Tracks.of.__func__  # type: ignore[attr-defined]

    def counted(cls: type[Tracks], table: pd.DataFrame) -> Tracks:
        whole.append(len(table))
        return of(cls, table)

    monkeypatch.setattr(mission_state.Tracks, "of", classmethod(counted))
    positions, seen, handed = Positions(), [], []
    positions.since(START)  # the run's start known from the first look on
    late = 0
    for batch in arriving(seed):
        late += bool(positions.size) and min(p.stamp for p in batch) < START.timestamp() + float(
            positions.table["s"].iloc[-1]
        )
        positions.add(batch)
        seen += batch
        table, tracks = positions.since(START)
        expected = afresh(seen)
        pd.testing.assert_frame_equal(table, expected)
        handed.append((table, expected))
        fresh = Tracks.of(expected)
        whole.pop()
        for window in ((-1.0, 100.0), (2.0, 5.05)):
            assert tracks.between(*window) == fresh.between(*window), window
    for table, expected in handed:
        pd.testing.assert_frame_equal(table, expected)
    assert late > 10  # the case this test is about happened
    assert whole == [0], whole  # only the first look's, of no samples
