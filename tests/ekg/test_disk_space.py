"""The estimate of Neo4j's disk space for a log, counted by hand for a small log."""

from __future__ import annotations

import pandas as pd

from robotale.ekg import disk_space


def test_the_estimate_counts_events_relationships_and_values_as_the_build_writes_them():
    events = pd.DataFrame(
        {
            "activity": ["go", "stop", "go", "wait"],  # 2 + 4 + 2 + 4 = 12 characters
            "robot": ["r1", "r1", "r2", None],  # 3 values of 2 characters
            "msg_id": [None, "m1", None, "m1"],  # 2 values of 2 characters
            "x": [1.0, 2.0, None, 4.0],  # 3 numbers of 8 bytes
        }
    )
    # CORR and DF for each of the 5 entity values, OBSERVED for 4 events of 2 class keys
    relationships = 2 * (3 + 2) + 2 * 4
    values = 12 + 3 * 2 + 2 * 2 + 3 * 8
    expected = disk_space.MARGIN * (
        4 * disk_space.PER_EVENT
        + relationships * disk_space.PER_RELATIONSHIP
        + values * disk_space.PER_VALUE_BYTE
    )
    assert disk_space.needed_bytes(events, ["robot", "msg_id", "absent"], 2) == int(expected)


def test_a_large_logs_values_are_measured_on_every_nth_row():
    rows = 3 * disk_space.SAMPLE + 2
    events = pd.DataFrame({"activity": ["abcd", "efghij"] * (rows // 2)})  # 5 bytes a row
    expected = (
        disk_space.MARGIN * (rows * disk_space.PER_EVENT + rows * disk_space.PER_RELATIONSHIP)
        + disk_space.MARGIN * disk_space.PER_VALUE_BYTE * 5 * rows
    )
    assert abs(disk_space.needed_bytes(events, [], 1) - expected) / expected < 0.01
