"""``compare`` against the truth of small written batches (``tests/conventions.py``): each run
of a drone and two tractors drawn at random, so every value per run the comparison tests
(the run's duration, each activity's mean duration and count per robot type, each robot
type's waits between two steps and how often it took each, the messages' latency, loss and
resends, the battery each robot used, the variant it follows; and, with positions written
on a straight drive, each robot's distance, region and meetings) is known here from the
truth's own instances, messages, samples and drives, never from the code under test; and
many pairs of
batches of the same settings, whose changes called significant are counted against the
chance the procedure allows."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
from conventions import GroundTruth, RunWriter, Sample, write_robotale_csv

from robotale.enhancement.bottlenecks import ALPHA
from robotale.enhancement.compare import compare_logs
from robotale.enhancement.performance import ARROW
from robotale.eventlog.readers import read_log

ROBOTS = {"drone": "Drone", "tractor_1": "Tractor", "tractor_2": "Tractor"}
RUNS = 10
#: false alarms allowed in twenty pairs of batches of the same settings
BOUND = 4
#: the messages of a run: (number, receiver, seconds after the start it is sent, whether it
#: may be lost): tractor_2's never is, so a lost message's receiver is tractor_1's, the
#: drone's usual receiver, for the truth and for a reader of the log alike
SENT = ((1, "tractor_1", 10.0, True), (2, "tractor_2", 15.0, False), (3, "tractor_1", 20.0, True))


def batch(
    seed: int,
    *,
    explore: float = 1.0,
    latency: float = 1.0,
    loss: float = 0.2,
    drain: float = 0.2,
    check: bool = False,
) -> GroundTruth:
    """``RUNS`` runs: the drone takes off, explores (``explore`` scales its time), sends
    three weed positions (tractor_1's each lost with chance ``loss``, the second of them
    then a resend of the first; received after ``latency`` times 1-2 s) and lands; the
    tractors move to the weeds (tractor_1 checks first when ``check``); times in eighths of
    a second (see :func:`_tick`). Activities start at fixed moments, so a run's variant
    depends only on which messages were lost; battery samples fall by ``drain`` times
    0.8-1.2 points a second."""
    rng = np.random.default_rng(seed)
    truth = GroundTruth(cases=[f"s{seed}r{n}" for n in range(RUNS)], robots=dict(ROBOTS))
    for n, case in enumerate(truth.cases):
        run = RunWriter(truth, case, pd.Timestamp("2024-05-01T08:00:00Z") + pd.Timedelta(hours=n))
        run.instance("drone", "takeoff", 0, 5)
        run.instance("tractor_2", "wait", 1, 24)
        run.instance("drone", "explore", 6, _tick(6 + explore * rng.uniform(30, 40)))
        first_lost = None
        for number, to, sent, losable in SENT:
            lost = losable and rng.random() < loss
            arrives = None if lost else _tick(sent + latency * rng.uniform(1, 2))
            # the next position for tractor_1 repeats the first when that one was lost
            again = first_lost if number == 3 else None
            message = run.message(number, to, sent, arrives, resend_of=again)
            first_lost = message if number == 1 and lost else first_lost
        if check:
            run.instance("tractor_1", "check", 24, _tick(24 + rng.uniform(1, 2)))
        run.instance("tractor_1", "move_to_weed", 26, _tick(26 + rng.uniform(15, 25)))
        run.instance("tractor_2", "move_to_weed", 27, _tick(27 + rng.uniform(15, 25)))
        run.instance("drone", "land", 80, _tick(80 + rng.uniform(3, 5)))
        for robot, activity, seconds, rate in (
            ("drone", "explore", (10, 20, 30), drain * rng.uniform(0.8, 1.2)),
            ("tractor_1", "move_to_weed", (30, 35, 40), 0.1),
        ):
            for second in seconds:
                level = round(100.0 - rate * second, 3)
                truth.samples.append(Sample(case, robot, activity, run.at(second), level))
    return truth


def _tick(seconds: float) -> float:
    """``seconds`` to an eighth of a second: exact in binary, so the CSV's milliseconds
    hold it whole."""
    return round(seconds * 8) / 8


def read(truth: GroundTruth, folder: Path, name: str) -> pd.DataFrame:
    return read_log(write_robotale_csv(truth, folder / f"{name}.csv"))


def _instances(truth: GroundTruth) -> pd.DataFrame:
    instances = truth.instance_table()
    return instances.assign(who=instances["robot"].map(ROBOTS))


def _steps(instances: pd.DataFrame) -> pd.DataFrame:
    """Each robot's consecutive activities in a run, and its wait between them: from the
    latest end of its activities so far to the next start."""
    ordered = instances.sort_values(["case", "robot", "start"])
    by_robot = ordered.groupby(["case", "robot"])
    steps = ordered.assign(
        target=by_robot["activity"].shift(-1),
        wait=(by_robot["start"].shift(-1) - by_robot["end"].cummax()).dt.total_seconds(),
    ).dropna(subset=["target"])
    return steps.assign(step=steps["activity"] + ARROW + steps["target"])


def expected_per_run(truth: GroundTruth, other: GroundTruth) -> pd.DataFrame:
    """(measure, subject, who, run) -> value, from the truth alone; an activity only the
    ``other`` batch did is done 0 times in each run of this one."""
    instances = _instances(truth)
    rows = []
    for case, own in instances.groupby("case"):
        rows.append(("run duration", "runs", "", case, (own["end"].max() - own["start"].min())))
    durations = instances.groupby(["activity", "who", "case"])["seconds"].mean()
    rows += [("activity duration", a, w, c, v) for (a, w, c), v in durations.items()]
    counts = instances.groupby(["activity", "who", "case"]).size().unstack("case", fill_value=0)
    both = counts.index.union(_instances(other).set_index(["activity", "who"]).index.unique())
    counts = counts.reindex(index=both, columns=truth.cases, fill_value=0)
    rows += [("activity frequency", a, w, c, float(v)) for (a, w), r in counts.iterrows()
             for c, v in r.items()]  # fmt: skip
    steps = _steps(instances)
    waits = steps.assign(wait=steps["wait"].clip(lower=0)).groupby(["step", "who", "case"])
    rows += [("transition wait", st, w, c, v) for (st, w, c), v in waits["wait"].mean().items()]
    taken = steps.groupby(["step", "who", "case"]).size().unstack("case", fill_value=0)
    both = taken.index.union(_steps(_instances(other)).set_index(["step", "who"]).index.unique())
    taken = taken.reindex(index=both, columns=truth.cases, fill_value=0)
    rows += [("transition frequency", st, w, c, float(v)) for (st, w), r in taken.iterrows()
             for c, v in r.items()]  # fmt: skip
    messages = pd.DataFrame([m.__dict__ for m in truth.messages])
    messages["lost"] = messages["received"].isna().astype(float)
    messages["latency"] = (messages["received"] - messages["sent"]).dt.total_seconds()
    for case, own in messages.groupby("case"):
        rows.append(("message loss", "weed_position", "", case, own["lost"].mean()))
        resends = float(own["resend_of"].notna().sum())
        rows.append(("message resends", "weed_position", "", case, resends))
        if own["latency"].notna().any():
            rows.append(("message latency", "weed_position", "", case, own["latency"].mean()))
    samples = pd.DataFrame([s.__dict__ for s in truth.samples]).sort_values("time")
    levels = samples.groupby(["robot", "case"])["battery"]
    used = levels.first() - levels.last()
    rows += [("battery used", "battery", robot, case, v) for (robot, case), v in used.items()]
    table = pd.DataFrame(rows, columns=["measure", "subject", "who", "run", "value"])
    seconds = table["value"].map(lambda v: v.total_seconds() if hasattr(v, "seconds") else v)
    return table.assign(value=seconds.astype(float)).set_index(["measure", "subject", "who", "run"])


def variants(truth: GroundTruth) -> pd.Series:
    """Per run, every robot's activities in start order (no two start at one moment)."""
    instances = truth.instance_table().sort_values(["case", "start"])
    return instances.groupby("case")["activity"].agg(tuple)


@pytest.fixture(scope="module")
def injected(tmp_path_factory):
    """A, and B with the drone exploring 1.5 times as long, messages twice as slow and lost
    half the time, its battery draining twice as fast and tractor_1 checking first."""
    folder = tmp_path_factory.mktemp("truth")
    a = batch(1)
    b = batch(2, explore=1.5, latency=2.0, loss=0.5, drain=0.4, check=True)
    return a, b, compare_logs(read(a, folder, "a"), read(b, folder, "b"))


def assert_side_is(got, side, expected, **tolerance):
    """One side's per-run values of the measures ``expected`` holds equal those values."""
    mine = got[got["side"] == side]["value"]
    mine = mine[mine.index.get_level_values("measure").isin(expected.index.levels[0])]
    assert sorted(mine.index) == sorted(expected.index)
    assert mine.sort_index().to_numpy() == pytest.approx(
        expected["value"].sort_index().to_numpy(), **tolerance
    )


def test_every_value_per_run_is_the_truths(injected):
    a, b, comparison = injected
    got = comparison.per_run.set_index(["measure", "subject", "who", "run"])
    for side, truth, other in ((0, a, b), (1, b, a)):
        assert_side_is(got, side, expected_per_run(truth, other), abs=1e-6)


def test_the_injected_changes_are_called_with_their_direction(injected):
    a, b, comparison = injected
    changes = comparison.changes.set_index(["measure", "subject", "who"]).sort_index()
    for key, sign in (
        (("activity duration", "explore", "Drone"), 1),
        (("message latency", "weed_position", ""), 1),
        (("battery used", "battery", "drone"), 1),
    ):
        row = changes.loc[key]
        truth = [
            expected_per_run(t, o).sort_index().loc[key]["value"].mean()
            for t, o in ((a, b), (b, a))
        ]
        assert (row["a"], row["b"]) == pytest.approx(truth)
        assert row["q_value"] < ALPHA and np.sign(row["difference"]) == sign
    # a step of tractor_1's that A never did: new in B, in each of its runs
    assert f"New in B: check by Tractor (in {RUNS} of {RUNS} runs of B)." in comparison.sentences


def test_variants_appeared_and_vanished_as_the_truth_has_them(injected):
    a, b, comparison = injected
    old, new = variants(a), variants(b)
    table = comparison.variants.assign(
        steps=comparison.variants["variant"].map(lambda v: tuple(v.split(ARROW)))
    ).set_index("steps")
    assert set(table.index) == set(old) | set(new)
    for steps, row in table.iterrows():
        assert (row["runs_a"], row["runs_b"]) == ((old == steps).sum(), (new == steps).sum())
        status = "both" if steps in set(old) and steps in set(new) else None
        status = status or ("appeared" if steps in set(new) else "vanished")
        assert row["status"] == status
    # tractor_1 checks in every run of B: no variant of A is left
    assert (table["status"] != "both").all()


@pytest.mark.slow
def test_same_settings_call_no_more_than_chance_over_many_pairs(tmp_path):
    """Twenty pairs of batches of the same settings, different seeds: nothing changed, so a
    pair with any change called significant (adjusted p below ``ALPHA``) is a false alarm,
    which the procedure allows in at most ``ALPHA`` of the pairs: more than ``BOUND`` in 20
    happens by chance less than once in a hundred. Each pair tests a dozen or more
    measures; that the same procedure sees a real change is checked on the injected
    batches above."""
    pairs, alarms, tested = 20, 0, []
    for n in range(pairs):
        logs = [read(batch(1000 + 2 * n + side), tmp_path, f"{n}_{side}") for side in (0, 1)]
        changes = compare_logs(*logs).changes
        tested.append(int(changes["q_value"].notna().sum()))
        alarms += bool((changes["q_value"] < ALPHA).any())
    assert min(tested) >= 10, tested
    tail = sum(
        math.comb(pairs, k) * ALPHA**k * (1 - ALPHA) ** (pairs - k)
        for k in range(BOUND + 1, pairs + 1)
    )
    assert tail < 0.01
    assert alarms <= BOUND, alarms


def test_the_first_bottleneck_moved_to_the_injected_wait(tmp_path):
    """The mission with injected findings (``tests/mission_findings.py``): B has a third of
    its runs wait for a refill, A none. B's first bottleneck is that wait, its cost per run
    what the runs with it take longer than the others (counted here from each run's first
    and last event) times their share; compared the other way round it is A's."""
    import mission_findings as mission

    from robotale.eventlog.schema import CASE, TIMESTAMP

    full = read_log(mission.write_injected("robotale.csv", tmp_path / "mission.csv"))
    calm = full[~full[CASE].isin(mission.REFILL_RUNS)].reset_index(drop=True)
    times = full.groupby(CASE)[TIMESTAMP]
    seconds = (times.max() - times.min()).dt.total_seconds()
    refill = seconds.index.isin(sorted(mission.REFILL_RUNS))
    cost = (seconds[refill].mean() - seconds[~refill].mean()) * refill.mean()
    said = f"activity at {mission.REFILL} by tractor_1, {cost:.1f}s per run"
    moved = [s for s in compare_logs(calm, full).sentences if "first bottleneck" in s]
    assert len(moved) == 1 and moved[0].startswith("The first bottleneck moved (in A: ")
    assert moved[0].endswith(f"in B: {said}).")
    back = [s for s in compare_logs(full, calm).sentences if "first bottleneck" in s]
    assert back[0].startswith(f"The first bottleneck moved (in A: {said}; in B: ")


# -- where the robots worked (the findings' third question) ----------------------------------

#: each robot drives straight at this speed (m/s) along x, and half as fast along y, from its
#: lane's start at the run's first event; the drone 10 m up, so it never meets a tractor
SPEEDS = {"drone": 2.0, "tractor_1": 0.5, "tractor_2": 0.5}
HEIGHT = {"drone": 10.0, "tractor_1": 0.0, "tractor_2": 0.0}


def placed(log: pd.DataFrame, lanes: dict[str, float], scale: float = 1.0) -> pd.DataFrame:
    """The log with a position on every event: ``scale`` times each robot's speed times the
    seconds since its run began, in x, half that in y from the robot's lane."""
    from robotale.eventlog.schema import CASE, ROBOT, TIMESTAMP

    since = (log[TIMESTAMP] - log.groupby(CASE)[TIMESTAMP].transform("min")).dt.total_seconds()
    speed = log[ROBOT].map(SPEEDS) * scale
    return log.assign(
        x=speed * since, y=log[ROBOT].map(lanes) + 0.5 * speed * since, z=log[ROBOT].map(HEIGHT)
    )


def spatial_truth(log: pd.DataFrame, scale: float) -> pd.DataFrame:
    """(measure, subject, who, run) -> value: a robot drives straight, so its distance is
    its speed (x and y together) times the seconds between its first and last event and its
    region is the x and y it covered multiplied; a robot type's is its robots' mean, and a
    robot has its own only beside another of its type."""
    from robotale.eventlog.schema import CASE, ROBOT, TIMESTAMP

    times = log.groupby([CASE, ROBOT])[TIMESTAMP]
    seconds = (times.max() - times.min()).dt.total_seconds()
    speed = seconds.index.get_level_values(ROBOT).map(SPEEDS).to_numpy() * scale
    along_x = speed * seconds
    robots = pd.DataFrame(
        {"distance": np.hypot(1.0, 0.5) * along_x, "region": along_x * 0.5 * along_x}
    ).reset_index()
    rows = []
    for measure, column in (("distance travelled", "distance"), ("region area", "region")):
        for (case, robot), value in robots.set_index([CASE, ROBOT])[column].items():
            if robot != "drone":  # the only drone is its type, Drone
                rows.append((measure, column, robot, case, value))
        typed = robots.assign(who=robots[ROBOT].map(ROBOTS)).groupby(["who", CASE])[column]
        rows += [(measure, column, w, c, v) for (w, c), v in typed.mean().items()]
    table = pd.DataFrame(rows, columns=["measure", "subject", "who", "run", "value"])
    return table.set_index(["measure", "subject", "who", "run"])


def meetings(log: pd.DataFrame) -> pd.Series:
    """Per run, how many times the tractors met when they drive side by side 1 m apart:
    each stretch of tractor_1's positions (in time order) with one of tractor_2's at most
    1 s away, since within 1 s they are at most 1.8 m apart."""
    from robotale.eventlog.schema import CASE, ROBOT, TIMESTAMP

    counts = {}
    for case, run in log.groupby(CASE):
        mine = np.sort(run.loc[run[ROBOT] == "tractor_1", TIMESTAMP].to_numpy())
        theirs = run.loc[run[ROBOT] == "tractor_2", TIMESTAMP].to_numpy()
        gaps = np.abs(mine[:, None] - theirs[None, :]).min(axis=1)
        near = gaps <= np.timedelta64(1, "s")
        counts[case] = int(np.sum(near & ~np.r_[False, near[:-1]]))
    return pd.Series(counts, dtype=float)


@pytest.fixture(scope="module")
def driven(tmp_path_factory):
    """A with the tractors 50 m apart; B driving twice as far, its tractors side by side."""
    folder = tmp_path_factory.mktemp("driven")
    a, b = read(batch(3), folder, "a"), read(batch(4), folder, "b")
    a = placed(a, {"drone": -100.0, "tractor_1": 0.0, "tractor_2": 50.0})
    b = placed(b, {"drone": -100.0, "tractor_1": 0.0, "tractor_2": 1.0}, scale=2.0)
    return a, b, compare_logs(a, b)


def test_where_the_robots_worked_is_the_truths_per_run(driven):
    a, b, comparison = driven
    got = comparison.per_run.set_index(["measure", "subject", "who", "run"])
    for side, log, scale in ((0, a, 1.0), (1, b, 2.0)):
        assert_side_is(got, side, spatial_truth(log, scale), rel=1e-9)
    met = got[got.index.get_level_values("measure") == "encounters"]
    assert set(met.index.get_level_values("who")) == {"Tractor and Tractor"}
    # A's tractors, 50 m apart, never meet: 0 in each of its runs
    for side, expected in ((0, meetings(a) * 0), (1, meetings(b))):
        counts = met[met["side"] == side]["value"].droplevel(["measure", "subject", "who"])
        assert counts.sort_index().to_dict() == expected.sort_index().to_dict()


def test_driving_twice_as_far_is_called_with_its_sign(driven):
    a, b, comparison = driven
    changes = comparison.changes.set_index(["measure", "subject", "who"])
    for who in ("Drone", "Tractor", "tractor_1"):
        row = changes.loc[("distance travelled", "distance", who)]
        key = ("distance travelled", "distance", who)
        truth = [spatial_truth(log, s).sort_index().xs(key)["value"]
                 for log, s in ((a, 1.0), (b, 2.0))]  # fmt: skip
        assert (row["a"], row["b"]) == pytest.approx([t.mean() for t in truth])
        assert row["q_value"] < ALPHA and row["difference"] > 0 and row["ranked"]
    assert any(s.startswith("Tractor travels ") and " farther per run" in s
               for s in comparison.sentences)  # fmt: skip
    met = changes.loc[("encounters", "encounters", "Tractor and Tractor")]
    assert met["a"] == 0 and met["b"] > 0 and met["q_value"] < ALPHA
    assert comparison.to_dict()["facts"]["positions"] == [True, True]


def test_a_log_without_positions_says_so(driven, injected):
    a, _, _ = driven
    without = injected[2]
    assert (
        "Neither A nor B has positions, so where the robots worked is not compared."
        in without.sentences
    )
    assert not without.changes["measure"].isin(("distance travelled", "encounters")).any()
    one_sided = compare_logs(a, a.drop(columns=["x", "y", "z"]))
    assert "B has no positions, so where the robots worked is not compared." in (
        one_sided.sentences
    )
