"""Fixtures for the discovery tests: the thesis log as a canonical event log."""

from pathlib import Path

import pandas as pd
import pytest

from robotale.ingest.schema import ACTIVITY, CASE, LIFECYCLE, ROBOT, TIMESTAMP


def read_thesis_log(path: Path) -> pd.DataFrame:
    """The thesis CSV in canonical columns, one case (it has no case column)."""
    table = pd.read_csv(path, dtype={"msg_id": "string", "field": "string"})
    table = table.rename(
        columns={"time": TIMESTAMP, "activity": ACTIVITY, "lifecycle": LIFECYCLE, "resource": ROBOT}
    )
    table[TIMESTAMP] = pd.to_datetime(table[TIMESTAMP])
    table[CASE] = "1"
    return table


@pytest.fixture(scope="session")
def thesis_log(thesis_csv) -> pd.DataFrame:
    return read_thesis_log(thesis_csv)
