"""Fixtures of the ekg tests."""

from __future__ import annotations

import os

import pandas as pd
import pytest

from robotale.eventlog.readers import read_csv


@pytest.fixture
def env(tmp_path, neo4j_server) -> dict[str, str]:
    """The environment of a `robotale` with a Neo4j home of its own under ``tmp_path/home``
    (neo4j_server first: it provisions the jar cache this second server shares)."""
    from robotale.neo4j_server import jars

    clean = {k: v for k, v in os.environ.items() if not k.startswith("NEO4J_")}
    return clean | {
        "ROBOTALE_HOME": str(tmp_path / "home"),
        "ROBOTALE_CACHE": str(jars.server_dir().parent),
        "ROBOTALE_NEO4J_HEAP": "512m",
        "ROBOTALE_NEO4J_PAGECACHE": "64m",
    }


@pytest.fixture(scope="module")
def thesis_log(thesis_csv) -> pd.DataFrame:
    """The thesis' CSV as robotale reads it (one case: it has no case column)."""
    return read_csv(thesis_csv)
