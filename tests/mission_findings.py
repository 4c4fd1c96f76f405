"""A mission of twelve runs with findings injected on purpose, written in the conventions of
``tests/conventions.py`` so the findings can be checked whichever tool wrote the log.

The injections (every expected answer is counted from this truth in the tests, never taken
from the code under test):

- **bottleneck**: in :data:`REFILL_RUNS` (a third of the runs) tractor_1 waits for a refill
  (:data:`REFILL`, an optional waiting activity) for :data:`REFILL_SECONDS` before it moves to
  the weed, and those runs end that much later (so they are also the most common variant). Its
  name says it waits, as does tractor_2's ``wait`` of every run: only the measured effect may
  rank it first;
- **delayed message**: in run :data:`DELAYED_RUN` the second weed position reaches tractor_1
  after :data:`DELAYED_LATENCY` seconds instead of 1.5 (the last to tractor_1, so nothing
  sent after it can pass for a resend);
- **lost message**: in :data:`LOST_RUNS` the position for tractor_2 is lost and resent under
  a new id;
- **low battery**: in :data:`LOW_BATTERY_RUNS` the drone raises a ``low_battery`` instant
  event and recharges for :data:`RECHARGE_SECONDS` before landing.
"""

from __future__ import annotations

import contextlib
from collections.abc import Iterator
from pathlib import Path

import conventions
import pandas as pd
import pytest
from conventions import GroundTruth, RunWriter, Sample

RUNS = [f"run{n:02d}" for n in range(1, 13)]
REFILL_RUNS = {"run02", "run05", "run08", "run11"}
REFILL_SECONDS = 300.0
REFILL = "wait_for_refill"
DELAYED_RUN = "run07"
DELAYED_LATENCY = 30.0
LOST_RUNS = {"run03", "run09"}
LOW_BATTERY_RUNS = {"run04", "run10"}
RECHARGE_SECONDS = 40.0
STARTS = {
    run: (pd.Timestamp("2024-03-04T08:00:00Z") + pd.Timedelta(hours=3 * n)).isoformat()
    for n, run in enumerate(RUNS)
}


def injected_truth() -> GroundTruth:
    truth = GroundTruth(cases=list(RUNS), robots=dict(conventions.ROBOTS))
    for run in RUNS:
        _run(truth, run, pd.Timestamp(STARTS[run]))
    return truth


def _run(truth: GroundTruth, case: str, begin: pd.Timestamp) -> None:
    """One run; no two activities start at the same moment, so the order is unambiguous."""

    run = RunWriter(truth, case, begin)
    at, instance, message = run.at, run.instance, run.message

    refill = REFILL_SECONDS if case in REFILL_RUNS else 0.0
    late = DELAYED_LATENCY if case == DELAYED_RUN else 1.5
    instance("drone", "takeoff", 0, 5)
    instance("tractor_2", "wait", 1, 46)
    instance("drone", "explore", 6, 40)
    message(1, "tractor_1", 20, 21.5)
    message(2, "tractor_1", 25, 25 + late)
    if case in LOST_RUNS:
        lost = message(3, "tractor_2", 30, None)
        message(4, "tractor_2", 44, 46.5, resend_of=lost)
    else:
        message(3, "tractor_2", 44, 46.5)
    if refill:
        instance("tractor_1", REFILL, 52, 52 + refill)
    instance("tractor_1", "move_to_weed", 53 + refill, 80 + refill)
    instance("tractor_2", "move_to_weed", 48, 70)
    land = 90.0  # the drone's own work never waits for tractor_1's refill
    if case in LOW_BATTERY_RUNS:
        instance("drone", "low_battery", 41, 41)
        instance("drone", "recharge", 42, 42 + RECHARGE_SECONDS)
        land += RECHARGE_SECONDS
    instance("drone", "land", land, land + 4)
    for robot, activity, seconds in (
        ("drone", "explore", (10, 20, 30)),
        ("tractor_2", "wait", (10, 20, 30, 40)),
        ("tractor_2", "move_to_weed", (50, 60)),
    ):
        for second in seconds:
            time = at(second)
            level = round(100.0 - 0.2 * second, 3)
            truth.samples.append(Sample(case, robot, activity, time, level))


@contextlib.contextmanager
def run_starts() -> Iterator[None]:
    """The writers of ``conventions`` that compute battery levels look up each run's start;
    these runs' starts are added for as long as the block runs."""
    with pytest.MonkeyPatch.context() as patch:
        for run, start in STARTS.items():
            patch.setitem(conventions.CASE_STARTS, run, start)
        yield


WRITERS = {
    "robotale.csv": conventions.write_robotale_csv,
    "inprogress.xes": conventions.write_inprogress_xes,
    "robot_id.csv": conventions.write_robot_id_csv,
}


def write_injected(convention: str, path: Path) -> Path:
    """The injected mission written as ``convention`` (a key of :data:`WRITERS`)."""
    with run_starts():
        return WRITERS[convention](injected_truth(), path)
