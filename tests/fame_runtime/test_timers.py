"""ISO 8601 timers: date, duration and cycle, as the thesis configures them (4.1.2)."""

import itertools
from datetime import UTC, datetime

import pytest

from robotale.fame_runtime.timers import parse_duration, parse_timer

EPOCH = datetime(2023, 10, 1, 12, 0, tzinfo=UTC).timestamp()


@pytest.mark.parametrize(
    ("text", "seconds"),
    [
        ("PT10S", 10),
        ("PT1H30M", 5400),
        ("P1DT2H", 93600),
        ("PT0.5S", 0.5),
        ("PT1,5S", 1.5),
        ("P1W", 604800),
        ("P1Y", 365 * 86400),
        ("P1M", 30 * 86400),
        ("PT1M", 60),
    ],
)
def test_durations(text, seconds):
    assert parse_duration(text) == seconds


@pytest.mark.parametrize("text", ["", "P", "PT", "10S", "PT-1S", "P1H", "PT1H30"])
def test_malformed_durations(text):
    with pytest.raises(ValueError, match="is not an ISO 8601 duration"):
        parse_duration(text)


def test_date_fires_at_that_instant_or_at_once_when_past():
    timer = parse_timer("timeDate", "2023-10-01T12:00:00Z")  # the thesis' example
    assert list(timer.fire_times(EPOCH - 60)) == [EPOCH]
    assert list(timer.fire_times(EPOCH + 60)) == [EPOCH + 60]
    assert parse_timer("timeDate", "2023-10-01T14:00:00+02:00").at == EPOCH  # a zone
    assert parse_timer("timeDate", "2023-10-01T12:00:00").at == EPOCH  # no zone: UTC


def test_duration_fires_once_after_it():
    assert list(parse_timer("timeDuration", "PT1H30M").fire_times(100.0)) == [100.0 + 5400]


def test_cycles():
    assert list(parse_timer("timeCycle", "R5/PT10S").fire_times(0.0)) == [10, 20, 30, 40, 50]
    assert list(parse_timer("timeCycle", "R3/PT1S").fire_times(7.0)) == [8, 9, 10]
    endless = parse_timer("timeCycle", "R/PT10S")
    assert endless.repeat is None
    assert list(itertools.islice(endless.fire_times(0.0), 100))[-1] == 1000
    starting = parse_timer("timeCycle", "R3/2023-10-01T12:00:00Z/PT1S")
    assert list(starting.fire_times(EPOCH - 5)) == [EPOCH, EPOCH + 1, EPOCH + 2]
    ending = parse_timer("timeCycle", "R/PT1S/2023-10-01T12:00:03Z")
    assert list(ending.fire_times(EPOCH)) == [EPOCH + 1, EPOCH + 2, EPOCH + 3]


@pytest.mark.parametrize("text", ["PT10S", "R5", "R5/PT10S/PT10S/x", "0 0 * * *"])
def test_malformed_cycles(text):
    with pytest.raises(ValueError, match="is not an ISO 8601"):
        parse_timer("timeCycle", text)


def test_placeholders_are_parsed_when_armed():
    timer = parse_timer("timeDuration", "PT${delay}S")
    assert timer.deferred and timer.text == "PT${delay}S"
