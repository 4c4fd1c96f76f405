"""TALE enrichment on tables: upper-closest samples, inprogress rows, pairing."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest
from bagbuilder import at

from robotale.errors import InputError
from robotale.eventlog import schema
from robotale.eventlog.enrich import (
    BATTERY,
    ODOM,
    Perspective,
    PreparationWarning,
    enrich,
    inprogress,
    pair_activities,
    parse_perspective,
    upper_closest,
)

CASE, TIME, ROBOT = schema.CASE, schema.TIMESTAMP, schema.ROBOT


def tag_table(*tags) -> pd.DataFrame:
    """(seconds, robot, activity, lifecycle) -> canonical tag rows of one case."""
    return pd.DataFrame(
        {
            CASE: "run",
            TIME: [at(t) for t, *_ in tags],
            ROBOT: [r for _, r, _, _ in tags],
            schema.ACTIVITY: [a for _, _, a, _ in tags],
            schema.LIFECYCLE: [lc for *_, lc in tags],
        }
    )


def test_upper_closest_equals_a_search_per_event_on_random_data():
    rng = np.random.default_rng(7)
    robots, cases = ["a", "b", "c"], ["r1", "r2"]
    samples = pd.DataFrame(
        {
            CASE: rng.choice(cases, 3000),
            ROBOT: rng.choice(robots, 3000),
            TIME: [at(t) for t in rng.uniform(0, 100, 3000).round(3)],
            "v": rng.normal(size=3000),
        }
    )
    events = pd.DataFrame(
        {
            CASE: rng.choice(cases, 500),
            ROBOT: rng.choice(robots, 500),
            TIME: [at(t) for t in rng.uniform(0, 101, 500).round(3)],
        }
    )
    got = upper_closest(events, samples)["v"].tolist()

    def by_search(event) -> float:
        mine = samples[(samples[CASE] == event[CASE]) & (samples[ROBOT] == event[ROBOT])]
        mine = mine.sort_values(TIME, kind="stable")
        later = mine[mine[TIME] >= event[TIME]]
        return later["v"].iloc[0] if len(later) else mine["v"].iloc[-1]

    assert got == [by_search(event) for _, event in events.iterrows()]


def test_a_sample_at_the_same_instant_counts_as_upper_closest():
    samples = pd.DataFrame({CASE: "run", ROBOT: "a", TIME: [at(1), at(2)], "v": [1.0, 2.0]})
    events = pd.DataFrame({CASE: "run", ROBOT: ["a", "a", "b"], TIME: [at(1), at(1.001), at(1)]})
    assert upper_closest(events, samples)["v"].tolist()[:2] == [1.0, 2.0]
    assert np.isnan(upper_closest(events, samples)["v"].iloc[2])  # b has no samples


def test_each_completion_closes_the_earliest_open_start_of_its_activity():
    tags = tag_table(
        (0, "a", "move", "start"),
        (1, "a", "move", "start"),
        (2, "b", "move", "complete"),  # another robot's: no start of its own
        (3, "a", "move", "complete"),
        (4, "a", "scan", "none"),
        (5, "a", "move", "complete"),
        (6, "a", "move", "complete"),
    )
    starts, completes, orphans = pair_activities(tags)
    assert list(zip(starts, completes, strict=True)) == [(0, 3), (1, 5)]
    assert orphans.tolist() == [2, 6]


@pytest.mark.parametrize(
    ("rate", "expected"),
    [
        (1.0, [1, 2, 3]),
        (2.0, [0.5, 1, 1.5, 2, 2.5, 3, 3.5]),
        (0.3, [10 / 3]),
        (0, []),
    ],
)
def test_inprogress_rows_fall_strictly_inside_each_activity_at_the_rate(rate, expected):
    tags = tag_table((0, "a", "move", "start"), (4, "a", "move", "complete"))
    rows = inprogress(tags, np.array([0]), np.array([1]), rate)
    assert rows[TIME].tolist() == [at(t).floor("ns") for t in expected]
    assert set(rows[schema.STATE]) <= {"inprogress"}
    assert set(rows[schema.LIFECYCLE]) <= {"none"}


def test_enrich_orders_inprogress_rows_between_their_start_and_complete():
    tags = tag_table(
        (0, "a", "move", "start"),
        (2, "a", "move", "complete"),
        (1, "b", "scan", "none"),
    )
    samples = pd.DataFrame({CASE: "run", ROBOT: "a", TIME: [at(t) for t in range(4)], "x": 0.0})
    log = enrich(tags, {"odom": samples}, rate=1.0)
    assert list(zip(log[TIME], log[ROBOT], log[schema.STATE], strict=True)) == [
        (at(0), "a", "none"),
        (at(1), "b", "none"),
        (at(1), "a", "inprogress"),
        (at(2), "a", "none"),
    ]


def test_enrich_warns_once_with_the_count_of_completions_without_start():
    tags = tag_table((1, "a", "land", "complete"), (2, "b", "land", "complete"))
    with pytest.warns(PreparationWarning) as caught:
        log = enrich(tags, {})
    assert len(caught) == 1
    assert str(caught[0].message).startswith("2 complete event(s) have no start and are kept")
    assert len(log) == 2


def test_a_negative_rate_is_refused():
    with pytest.raises(InputError, match="rate must be 0 or more"):
        enrich(tag_table((0, "a", "x", "none")), {}, rate=-1)


def test_perspectives_from_their_command_line_form():
    assert parse_perspective("odom") == ODOM
    assert parse_perspective(" battery") == BATTERY
    moved = parse_perspective("odom=/*/odometry/filtered")
    assert (moved.topic, moved.columns) == ("/*/odometry/filtered", ODOM.columns)
    assert parse_perspective("range=/*/range:range") == Perspective(
        "range", "/*/range", {"range": "range"}
    )
    assert ODOM.matches("/drone/odom") and ODOM.matches("/odom")
    assert not ODOM.matches("/drone/odom/raw")
    for bad in ("lidar", "speed=/*/cmd_vel", "2fast=/*/x:y", "range=range:range"):
        with pytest.raises(InputError):
            parse_perspective(bad)
