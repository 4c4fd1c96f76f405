"""Fuzzed rosbag2 recordings: real bags (sqlite3 and MCAP, written by ``bagbuilder``) whose
storage file or metadata.yaml is cut, overwritten or spliced. Reading one gives tables or
robotale's own error, never another exception.

A few hundred examples per run; `make fuzz` runs many more (ROBOTALE_FUZZ_EXAMPLES)."""

from __future__ import annotations

import os
import shutil
import tempfile
from collections.abc import Iterator
from pathlib import Path

import pytest
from bagbuilder import BagBuilder
from hypothesis import HealthCheck, example, given, settings
from hypothesis import strategies as st

from robotale.errors import RobotaleError
from robotale.eventlog.prepare import prepare
from robotale.eventlog.rosbag import read_bag

FUZZ = settings(
    max_examples=int(os.environ.get("ROBOTALE_FUZZ_EXAMPLES", "200")),
    deadline=None,
    suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large],
)


@pytest.fixture(scope="module")
def bags() -> Iterator[dict[str, Path]]:
    """One small recording per storage format, and a folder to copy them into."""
    with tempfile.TemporaryDirectory() as work:
        folder = Path(work)
        written = {}
        for storage in ("sqlite3", "mcap"):
            b = BagBuilder().odom(1, "drone", 1.5, -2, 3).battery(1, "drone", 0.9)
            b.tag(1.5, "drone", "explore", "start", "m1", "send", "{}")
            b.tag(2.5, "drone", "explore", "complete")
            written[storage] = b.write(folder / storage, storage=storage)
        written["work"] = folder / "fuzzed"
        yield written


def _storage_file(bag: Path) -> Path:
    return next(p for p in sorted(bag.iterdir()) if p.suffix in (".db3", ".mcap"))


@st.composite
def damage(draw) -> tuple[str, str, list[tuple[float, float, bytes]]]:
    """Which bag, which of its files, and cuts (start and end as fractions, replacement)."""
    storage = draw(st.sampled_from(["sqlite3", "mcap"]))
    target = draw(st.sampled_from(["storage", "metadata"]))
    fraction = st.floats(0, 1)
    cuts = draw(
        st.lists(
            st.tuples(
                fraction, fraction, st.binary(max_size=16) | st.sampled_from([b"", b"\0" * 8])
            ),
            min_size=1,
            max_size=4,
        )
    )
    return storage, target, cuts


def damaged_copy(bags: dict[str, Path], storage: str, target: str, cuts) -> Path:
    copy = bags["work"]
    shutil.rmtree(copy, ignore_errors=True)
    shutil.copytree(bags[storage], copy)
    file = _storage_file(copy) if target == "storage" else copy / "metadata.yaml"
    data = bytearray(file.read_bytes())
    for first, last, replacement in cuts:
        start = int(first * len(data))
        end = max(start, min(len(data), start + int(last * 64)))
        data[start:end] = replacement
    file.write_bytes(bytes(data))
    return copy


@FUZZ
@given(case=damage())
# found by fuzzing: an MCAP index naming an impossible size, a truncated SQLite file
@example(case=("mcap", "storage", [(0.5, 0.6875, b"\x00\x00\x00\x00\x00")]))
@example(case=("sqlite3", "storage", [(0.875, 1.0, b"")]))
def test_damaged_bags(bags, case):
    bag = damaged_copy(bags, *case)
    try:
        read_bag(bag)
        prepare(bag)
    except RobotaleError:
        pass
