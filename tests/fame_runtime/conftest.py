"""Fixtures for the FAME runtime tests."""

from pathlib import Path

import pytest

MODELS = Path(__file__).resolve().parent / "models"


@pytest.fixture(scope="session")
def models() -> Path:
    """The semantics suite: one small .bpmn per element or pattern."""
    return MODELS
