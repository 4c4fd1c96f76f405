"""The preparation of a stored log's pages computes what it computed before it was made
faster (digests of every result, written by the earlier code: ``prepared.py``), with the
class graph built by the ingest's own tables where the earlier code aggregated it in Neo4j,
and its CPU time grows no faster than the log."""

from __future__ import annotations

import json
import time
import uuid
from collections.abc import Iterator

import pytest
from prepared import FIXTURE, digests, result_files, store, synthetic_log

from robotale.ekg.keys import built_keys
from robotale.results.background import prepare_now

EXPECTED = json.loads(FIXTURE.read_text())
#: how much more CPU time per event 100,000 events may take than 10,000: a preparation
#: that grows with the square takes ten times more
GROWTH = 1.5


def prepared_digests(driver, name: str, size: int, aggregate=None) -> tuple[dict, float]:
    """Store the synthetic log of ``size`` events, prepare its pages; their digests and the
    preparation's CPU seconds in this process."""
    store(driver, synthetic_log(size), name, aggregate)
    started = time.process_time()
    prepare_now(driver, name)
    seconds = time.process_time() - started
    return digests(result_files(driver, name), name), seconds


@pytest.fixture(scope="module")
def activity_10000(neo4j_driver) -> Iterator[tuple[dict, float]]:
    """The 10,000 events stored with the class graph by activity (as the digests were
    written) and prepared once: their digests and CPU seconds, for the test of those digests
    and as the 100,000 events' measure of linear time."""
    from robotale.ekg.logs import delete_log

    name = f"test_prepared_10000_{uuid.uuid4().hex[:8]}"
    try:
        yield prepared_digests(neo4j_driver, name, 10_000, ["activity"])
    finally:
        delete_log(neo4j_driver, name)


@pytest.mark.parametrize("keys", [pytest.param("activity", marks=pytest.mark.slow), "built"])
def test_the_pages_of_10000_events_are_those_prepared_before(request, log_name, keys):
    # "activity": the class graph is aggregated in Neo4j on preparing, as it was (the log the
    # 100,000 events' test measures against);
    # "built": the ingest's default keys build it from the tables in memory: the same graph
    if keys == "activity":
        found, _ = request.getfixturevalue("activity_10000")
    else:
        driver = request.getfixturevalue("neo4j_driver")
        found, _ = prepared_digests(driver, log_name, 10_000, built_keys(["robot", "msg_id"]))
    assert found == EXPECTED["10000"]


@pytest.mark.slow
def test_100000_events_are_prepared_as_before_in_linear_cpu_time(
    neo4j_driver, log_name, activity_10000
):
    found_small, seconds_small = activity_10000
    found, seconds = prepared_digests(neo4j_driver, log_name, 100_000)
    assert found_small == EXPECTED["10000"]
    assert found == EXPECTED["100000"]
    per_event_small, per_event = seconds_small / 10_000, seconds / 100_000
    assert per_event <= GROWTH * per_event_small, (
        f"{seconds_small:.1f} s CPU for 10,000 events, {seconds:.1f} s for 100,000: "
        f"{per_event / per_event_small:.2f}x per event"
    )
