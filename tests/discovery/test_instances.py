from collections import deque

import numpy as np
import pandas as pd

from robotale.discovery.instances import activity_instances
from robotale.eventlog.schema import ACTIVITY, CASE, LIFECYCLE, ROBOT, STATE, TIMESTAMP

T0 = pd.Timestamp("2024-01-01T10:00:00+00:00")


def log_of(rows, **extra) -> pd.DataFrame:
    log = pd.DataFrame(rows, columns=[ACTIVITY, LIFECYCLE, "t", *extra])
    log[TIMESTAMP] = T0 + pd.to_timedelta(log.pop("t"), unit="s")
    return log.assign(**{CASE: "1", ROBOT: "r"})


def test_execution_ids_pair_overlapping_runs_of_one_activity():
    # two scans overlap; the second finishes first: first in, first out would pair them wrongly
    log = log_of(
        [("scan", "start", 0, "a"), ("scan", "start", 1, "b"), ("scan", "complete", 3, "b"),
         ("scan", "complete", 10, "a")],
        execution_id=None,
    )  # fmt: skip
    instances = activity_instances(log).set_index("execution_id")
    assert instances.loc["a", "duration"] == 10.0 and instances.loc["b", "duration"] == 2.0
    fifo = activity_instances(log.drop(columns="execution_id"))
    assert sorted(fifo["duration"]) == [3.0, 9.0]  # what pairing without ids gives


def test_instants_lone_completions_and_open_starts():
    log = log_of(
        [
            ("timer", "none", 0),
            ("move", "complete", 2),  # its start was not recorded
            ("cut", "start", 3),  # never completes
        ]
    )
    instances = activity_instances(log).set_index(ACTIVITY)
    assert instances.loc["timer", "duration"] == 0.0 and instances.loc["timer", "finished"]
    assert instances.loc["move", "duration"] == 0.0
    assert not instances.loc["cut", "finished"] and pd.isna(instances.loc["cut", "duration"])
    assert list(instances.index) == ["timer", "move", "cut"]


def test_start_values_are_carried_and_inprogress_rows_ignored():
    log = log_of(
        [("fly", "start", 0, 90.0, "none"), ("fly", "none", 5, 80.0, "inprogress"),
         ("fly", "complete", 10, 70.0, "none")],
        battery=None,
        **{STATE: None},
    )  # fmt: skip
    instances = activity_instances(log, carry=["battery"])
    assert len(instances) == 1
    assert instances.loc[0, ["start_battery", "battery", "duration"]].tolist() == [90.0, 70.0, 10.0]


def test_ties_follow_the_documented_rule():
    # everything at one instant (a simulated clock), one robot: its starts keep the order it
    # tagged them in, and each completion finds its own start wherever it was written
    rows = [
        ("go_home", "start", 0),
        ("fly_back", "start", 0),
        ("fly_back", "complete", 0),
        ("go_home", "complete", 0),
    ]
    for written, first in (
        (rows, "go_home"),
        (rows[::-1], "fly_back"),
        (rows[2:] + rows[:2], "go_home"),
    ):
        instances = activity_instances(log_of(written))
        assert list(instances[ACTIVITY]) == [first, ({"go_home", "fly_back"} - {first}).pop()]
        assert instances["duration"].tolist() == [0.0, 0.0]
        assert instances["finished"].all()


def _loop_pairing(log: pd.DataFrame) -> list[tuple]:
    """Activity instances by hand: the events in time order, one queue of open starts per
    case, robot and activity, each end taking the oldest open start."""
    ends = {"complete", "ate_abort", "withdraw", None}  # a missing lifecycle completes
    open_starts: dict[tuple, deque] = {}
    found = []
    for event in log.sort_values(TIMESTAMP).to_dict("records"):
        key = (event[CASE], event[ROBOT], event[ACTIVITY])
        when = event[TIMESTAMP]
        lifecycle = None if pd.isna(event[LIFECYCLE]) else event[LIFECYCLE]
        queue = open_starts.setdefault(key, deque())
        if lifecycle == "start":
            queue.append(when)
        elif lifecycle == "none":
            found.append((*key, lifecycle, when, when, True, True))
        elif lifecycle in ends:
            began = queue.popleft() if queue else None
            found.append((*key, lifecycle, began or when, when, True, began is not None))
    for key, queue in open_starts.items():
        found += [(*key, "start", began, pd.NaT, False, True) for began in queue]
    return sorted(found, key=lambda instance: (instance[0], instance[4]))


def test_pairing_equals_a_loop_on_random_logs():
    # interleaved starts and ends of one activity, ends without a start, starts that never
    # end, aborted and withdrawn ends, instants, a missing lifecycle and one pairing ignores
    lifecycles = ["start", "start", "complete", "ate_abort", "withdraw", "none", None, "sample"]
    for seed in range(20):
        rng = np.random.default_rng(seed)
        size = 40
        log = pd.DataFrame(
            {
                CASE: rng.choice(["c1", "c2"], size),
                ROBOT: rng.choice(["r1", "r2"], size),
                ACTIVITY: rng.choice(["scan", "move"], size),
                LIFECYCLE: rng.choice(np.array(lifecycles, dtype=object), size),
                # distinct times, the rows not in time order
                TIMESTAMP: T0 + pd.to_timedelta(rng.permutation(size), unit="s"),
            }
        )
        instances = activity_instances(log)
        columns = [CASE, ROBOT, ACTIVITY, LIFECYCLE, "start_timestamp", TIMESTAMP]
        found = [
            tuple(None if pd.isna(value) else value for value in row)
            for row in instances[[*columns, "finished", "start_known"]].to_numpy(object)
        ]
        expected = [
            tuple(None if pd.isna(value) else value for value in row) for row in _loop_pairing(log)
        ]
        assert found == expected, seed
