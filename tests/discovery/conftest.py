"""Fixtures for the discovery tests: the thesis log, and logs the engine produces."""

import pandas as pd
import pytest

from robotale.eventlog.readers import read_log
from robotale.eventlog.schema import (
    ACTIVITY,
    CASE,
    LIFECYCLE,
    MSG_ID,
    MSG_ROLE,
    ROBOT,
    TIMESTAMP,
)


@pytest.fixture(scope="session")
def thesis_log(thesis_csv) -> pd.DataFrame:
    """The thesis CSV read as robotale reads it: one case (it has no case column)."""
    return read_log(thesis_csv)


def tags_to_log(tags, case: str) -> pd.DataFrame:
    """The tags of one mission run as an event log of one case."""
    return pd.DataFrame(
        {
            CASE: case,
            TIMESTAMP: pd.to_datetime([t.stamp for t in tags], unit="s", utc=True),
            ACTIVITY: [t.activity for t in tags],
            LIFECYCLE: [t.lifecycle for t in tags],
            ROBOT: [t.robot for t in tags],
            MSG_ID: [t.msg_id or None for t in tags],
            MSG_ROLE: [t.msg_role or None for t in tags],
        }
    )


@pytest.fixture(scope="session")
def engine_log():
    """Runs a model with robotale's engine (in-process bus, simulated clock) and returns the
    tags it left as an event log: ``engine_log(model, case, robots=..., variables=...)``."""
    from robotale.fame_runtime.bus import InProcessBus
    from robotale.fame_runtime.clock import SimClock
    from robotale.fame_runtime.mission import Mission

    def run(model, case="1", *, latency=0.0, until=None, **options) -> pd.DataFrame:
        tags: list = []
        clock = SimClock()
        mission = Mission(
            model,
            clock=clock,
            bus=InProcessBus(clock, latency=latency),
            tag_sink=tags.append,
            **options,
        )
        mission.run(until=until)
        return tags_to_log(tags, case)

    return run
