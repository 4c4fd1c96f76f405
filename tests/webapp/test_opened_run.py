"""Which run a stored upload opens on the Mission page, on a log whose answer is counted by
hand: run "b" is listed second but began first."""

from __future__ import annotations

import pandas as pd

from robotale.eventlog.schema import ACTIVITY, CASE, TIMESTAMP
from robotale.webapp.opened_run import opened_run

LOG = pd.DataFrame(
    {
        CASE: ["a", "a", "b", "b"],
        TIMESTAMP: pd.to_datetime(
            [
                "2024-01-01T10:00:05Z",
                "2024-01-01T10:00:01Z",
                "2024-01-01T10:00:03Z",
                "2024-01-01T10:00:02Z",
            ]
        ),
        ACTIVITY: ["go", "stop", "go", "stop"],
    }
)


def test_a_recording_opens_the_run_that_began_first():
    # a began at :01 (its second row), b at :02: a, though b's first row is earlier than a's
    assert opened_run("zip", LOG) == {"mission": "a"}
    assert opened_run("zip", LOG.iloc[2:]) == {"mission": "b"}


def test_a_table_of_events_or_an_empty_log_opens_none():
    assert opened_run("csv", LOG) == {}
    assert opened_run("xes", LOG) == {}
    assert opened_run("zip", LOG.iloc[:0]) == {}
