"""Fixtures of the ingest tests: bags written with known values (see ``bagbuilder``)."""

import pytest
from bagbuilder import BagBuilder


@pytest.fixture
def bag_builder():
    """The :class:`~bagbuilder.BagBuilder` class: call it for a fresh, empty recording."""
    return BagBuilder
