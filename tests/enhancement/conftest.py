"""Fixtures for the enhancement tests: the thesis log and small hand-made logs."""

from collections.abc import Callable

import pandas as pd
import pytest

from robotale.eventlog.readers import read_log
from robotale.eventlog.schema import ACTIVITY, CASE, LIFECYCLE, TIMESTAMP

BASE = pd.Timestamp("2024-01-01T10:00:00+00:00")


@pytest.fixture(scope="session")
def thesis_log(thesis_csv) -> pd.DataFrame:
    """The thesis CSV read as robotale reads it: one case (it has no case column)."""
    return read_log(thesis_csv)


@pytest.fixture
def events() -> Callable[..., pd.DataFrame]:
    """Builds a canonical log from dictionaries with ``t`` in seconds after a fixed start."""

    def build(*rows: dict) -> pd.DataFrame:
        log = pd.DataFrame(rows).rename(
            columns={"case": CASE, "activity": ACTIVITY, "lifecycle": LIFECYCLE}
        )
        log[TIMESTAMP] = BASE + pd.to_timedelta(log.pop("t"), unit="s")
        return log

    return build
