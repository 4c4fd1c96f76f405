"""Fixtures shared by every part's tests.

Each part keeps its own fixtures in ``tests/<part>/conftest.py``; only what several parts use
lives here.
"""

from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parent.parent
EXAMPLES = REPO / "examples"


@pytest.fixture(scope="session")
def thesis_csv() -> Path:
    """The event log the thesis' authors recorded from their running scenario (70 runs)."""
    return EXAMPLES / "thesis" / "robotic_data.csv"


@pytest.fixture(scope="session")
def fame_models() -> Path:
    """The thesis authors' own FAME models (fame-modeler/ and fame-ros/)."""
    return EXAMPLES / "thesis" / "fame-models"
