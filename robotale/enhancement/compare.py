"""What changed between two batches of runs (A, the earlier or reference batch, and B).

Every comparison takes the run as its unit: a run is one independent draw of the mission,
while the activities inside one run share its weeds, its batteries and its timing. Each
measure is therefore reduced to one value per run first (a run's duration; the mean duration
of an activity in the run, per robot type; how often the run does it; the mean wait of a
transition and how often the run takes it; the mean latency, the share lost and the resends
of a message type; the battery a robot used; how far each robot type travelled, the area of
the box its positions span and how often robots of two types met, the findings' third
question; whether the run follows a variant), and B's runs
are compared with A's by the Mann-Whitney U test (:func:`mann_whitney`: the statistic of
:mod:`robotale.enhancement.effects`, for every measure at once) and by Welch's t-test of the
means (:func:`welch`), which sees a mean moved by a few runs that the ranks barely notice;
a measure's p-value is the smaller of the two, Bonferroni-corrected (:func:`either`).

A comparison of two batches asks many questions at once, so some p-values come out small by
chance alone; the p-values are adjusted by the Benjamini-Hochberg procedure across all of
them (``q_value``), which keeps the expected share of false discoveries among the changes
called significant at :data:`~robotale.enhancement.bottlenecks.ALPHA`, and when nothing
changed at all, the chance of calling anything significant at that level too.

The changes are ranked as the findings rank bottlenecks
(:func:`robotale.enhancement.findings.trusted_first`): a change is *ranked* when it is both
sure (adjusted p below ``ALPHA``) and large (``share`` at least
:data:`~robotale.enhancement.bottlenecks.MIN_SHARE`), ranked changes before the others, each
part largest first. ``share`` puts the measures on one scale: for a time, the seconds it adds
to or takes from a run over A's mean run duration; for a battery use or a latency, the change
relative to A; for a share (of messages lost, of runs following a variant), the difference.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

import numpy as np
import pandas as pd

from robotale.discovery.graph import json_ready
from robotale.discovery.instances import DURATION
from robotale.enhancement.battery import battery_perspective
from robotale.enhancement.bottlenecks import ALPHA, MIN_SHARE, find_bottlenecks
from robotale.enhancement.communication import communication_perspective
from robotale.enhancement.context import LogAnalysis
from robotale.enhancement.encounters import encounters, positions
from robotale.enhancement.findings import seconds_text, trusted_first
from robotale.enhancement.performance import (
    ARROW,
    VARIANT,
    WAIT,
    finished_instances,
    shared_case_variants,
    shared_cases,
    shared_steps,
)
from robotale.eventlog.schema import ACTIVITY, CASE, ROBOT, ROBOT_TYPE, TIMESTAMP, X, Y, Z

#: the measures, in the order of the tables; each compares one value per run
MEASURES = (
    "run duration",
    "activity duration",
    "activity frequency",
    "transition wait",
    "transition frequency",
    "message latency",
    "message loss",
    "message resends",
    "battery used",
    "distance travelled",
    "region area",
    "encounters",
    "variant share",
)
#: the measures of where the robots worked (the findings' third question)
SPATIAL = ("distance travelled", "region area", "encounters")
#: the measures in seconds, whose share is the time they add to a run
TIMED = (
    "run duration",
    "activity duration",
    "activity frequency",
    "transition wait",
    "transition frequency",
)
COLUMNS = [
    "measure",
    "subject",
    "who",
    "runs_a",
    "runs_b",
    "a",
    "b",
    "difference",
    "relative",
    "share",
    "p_value",
    "q_value",
    "ranked",
    "sentence",
]
#: a variant needs this many runs, in A and B together, to be tested: fewer can never differ
VARIANT_RUNS = 2


@dataclass(slots=True)
class Batch:
    """One batch's per-run values: the runs' durations and each measure's long table
    (``subject``, ``who``, ``run``, ``value``)."""

    name: str
    analysis: LogAnalysis
    runs: pd.Series  # seconds, by run
    robots: list[str]
    values: dict[str, pd.DataFrame] = field(default_factory=dict)
    variants: pd.Series = field(default_factory=lambda: pd.Series(dtype=str))
    #: whether the log has positions (x and y of a robot): without, nothing spatial is known
    placed: bool = False


@dataclass(slots=True)
class Comparison:
    """The sentences (most important first), the table of every change tested and the
    tables of variants and bottlenecks."""

    names: tuple[str, str]
    sentences: list[str]
    changes: pd.DataFrame
    variants: pd.DataFrame
    bottlenecks: pd.DataFrame
    facts: dict[str, Any]
    #: every value per run behind ``changes`` (``measure``, ``subject``, ``who``, ``run``,
    #: ``value``, ``side``: 0 for A, 1 for B), for figures of the two batches' spread
    per_run: pd.DataFrame = field(default_factory=pd.DataFrame)

    def to_dict(self) -> dict[str, Any]:
        return json_ready(
            {
                "batches": list(self.names),
                "sentences": self.sentences,
                "facts": self.facts,
                "changes": self.changes.to_dict("records"),
                "variants": self.variants.to_dict("records"),
                "bottlenecks": self.bottlenecks.to_dict("records"),
            }
        )


def compare_logs(
    log_a: pd.DataFrame, log_b: pd.DataFrame, *, names: tuple[str, str] = ("A", "B")
) -> Comparison:
    """What changed from ``log_a`` to ``log_b`` (two canonical event logs)."""
    first, second = batch(log_a, names[0]), batch(log_b, names[1])
    per_run = per_run_values(first, second)
    changes = _changes(per_run, first, second)
    variants = variant_table(first, second)
    bottlenecks = bottleneck_table(first, second)
    facts = {
        "runs": [len(first.runs), len(second.runs)],
        "robots": [first.robots, second.robots],
        "tested": int(changes["q_value"].notna().sum()),
        "positions": [first.placed, second.placed],
        "significant": int((changes["q_value"] < ALPHA).sum()),
        "alpha": ALPHA,
    }
    sentences = _sentences(first, second, changes, variants, bottlenecks)
    return Comparison(names, sentences, changes, variants, bottlenecks, facts, per_run)


# -- the values per run ------------------------------------------------------------------------


def batch(log: pd.DataFrame, name: str) -> Batch:
    analysis = LogAnalysis(log)
    cases = shared_cases(analysis)
    runs = pd.Series(cases["duration"].to_numpy(float), index=cases[CASE].astype(str))
    robots = sorted(log[ROBOT].dropna().astype(str).unique()) if ROBOT in log.columns else []
    found = Batch(name, analysis, runs, robots)
    who = _who(log)
    instances = finished_instances(analysis)
    found.values["activity duration"] = _per_run(instances, who, ACTIVITY, DURATION, "mean")
    found.values["activity frequency"] = _frequencies(instances, who, runs.index)
    steps = shared_steps(analysis)
    steps = steps.assign(_step=steps["source"].astype(str) + ARROW + steps["target"].astype(str))
    found.values["transition wait"] = _per_run(steps.dropna(subset=[WAIT]), who, "_step", WAIT)
    found.values["transition frequency"] = _frequencies(steps, who, runs.index, "_step")
    found.values.update(_message_values(analysis))
    found.values["battery used"] = _battery_values(analysis)
    found.placed, spatial = _spatial_values(log, who)
    found.values.update(spatial)
    paths = shared_case_variants(analysis)
    found.variants = pd.Series(paths[VARIANT].to_numpy(), index=paths[CASE].astype(str))
    return found


def _who(log: pd.DataFrame) -> Callable[[pd.Series], pd.Series]:
    """The robot type of a robot column where the log names types (robots of one type are
    compared as one: a batch with one tractor less still has tractors), else the robot."""
    if ROBOT not in log.columns:
        return lambda robots: pd.Series("", index=robots.index)
    if ROBOT_TYPE not in log.columns:
        return lambda robots: robots.astype("string").fillna("")
    pairs = log[[ROBOT, ROBOT_TYPE]].dropna().drop_duplicates(ROBOT)
    types = dict(zip(pairs[ROBOT].astype(str), pairs[ROBOT_TYPE].astype(str), strict=True))
    return lambda robots: robots.astype(str).map(types).fillna(robots.astype(str))


def _per_run(
    rows: pd.DataFrame, who: Callable, subject: str, value: str, how: str = "mean"
) -> pd.DataFrame:
    """One value per run, subject and robot type (``how`` of ``value`` over its rows)."""
    if rows.empty:
        return _long([], [], [], [])
    robots = rows[ROBOT] if ROBOT in rows.columns else pd.Series("", index=rows.index)
    frame = pd.DataFrame(
        {
            "subject": rows[subject].astype(str).to_numpy(),
            "who": who(robots).to_numpy(),
            "run": rows[CASE].astype(str).to_numpy(),
            "value": pd.to_numeric(rows[value], errors="coerce").to_numpy(float),
        }
    )
    grouped = frame.groupby(["subject", "who", "run"], sort=True)["value"].agg(how)
    return grouped.dropna().reset_index()


def _frequencies(
    rows: pd.DataFrame, who: Callable, runs: pd.Index, subject: str = ACTIVITY
) -> pd.DataFrame:
    """How often each run does each activity (or takes each step: ``subject``) per robot
    type, 0 in the runs without it."""
    # only the columns counted: the rows' others are not copied
    read = [c for c in (ROBOT, subject, CASE) if c in rows.columns]
    counted = _per_run(rows[read].assign(_one=1.0), who, subject, "_one", "sum")
    if counted.empty:
        return counted
    wide = counted.pivot_table(
        index="run", columns=["subject", "who"], values="value", aggfunc="sum"
    )
    wide = wide.reindex(runs.rename("run")).fillna(0.0)
    return wide.stack(["subject", "who"], future_stack=True).rename("value").reset_index()


def _message_values(analysis: LogAnalysis) -> dict[str, pd.DataFrame]:
    """Per run and message type: the mean latency of the received, the share lost and how
    many times its messages were sent again (under the same id or a new one)."""
    messages = communication_perspective(analysis)
    if not messages.has_data or messages.tables["messages"].empty:
        empty = _long([], [], [], [])
        return {"message latency": empty, "message loss": empty, "message resends": empty}
    table = messages.tables["messages"]
    table = table.assign(
        _type=table["message_type"].astype(str).str.rstrip("!?"),
        _lost=table["lost"].astype(float),
        _resends=table["resends"].astype(float),
        **{CASE: table["case"].astype(str)},
    )

    def nobody(rows: pd.Series) -> pd.Series:
        return pd.Series("", index=rows.index)

    received = table[table["received"].astype(bool)]
    return {
        "message latency": _per_run(received, nobody, "_type", "latency"),
        "message loss": _per_run(table, nobody, "_type", "_lost"),
        "message resends": _per_run(table, nobody, "_type", "_resends", "sum"),
    }


def _battery_values(analysis: LogAnalysis) -> pd.DataFrame:
    """Per run and robot: the battery it used (percentage points)."""
    battery = battery_perspective(analysis)
    energy = battery.tables.get("energy", pd.DataFrame()) if battery.has_data else None
    if energy is None or energy.empty or "robot" not in energy.columns:
        return _long([], [], [], [])
    return _long(
        ["battery"] * len(energy),
        energy["robot"].astype(str),
        energy["case"].astype(str),
        energy["used"].astype(float),
    )


def _spatial_values(log: pd.DataFrame, who: Callable) -> tuple[bool, dict[str, pd.DataFrame]]:
    """Whether the log has positions and, per run: how far each robot travelled (metres, in
    3D, straight between consecutive positions, as :mod:`robotale.enhancement.spatial` takes
    a path), the area of the x-y box its positions span (the findings' region, on the
    ground), both as the mean of a robot type's robots and per robot where its type has
    several (matched by name with the other batch's); and how many times robots of two
    types met (an encounter of :mod:`robotale.enhancement.encounters`), per pair of
    types."""
    empty = {measure: _long([], [], [], []) for measure in SPATIAL}
    placed = positions(log)
    if placed.empty:
        return False, empty
    placed = placed.assign(
        **{CASE: placed[CASE].astype(str), ROBOT: placed[ROBOT].astype(str)}
    ).sort_values([CASE, ROBOT, TIMESTAMP], kind="stable")
    xyz = placed[[X, Y, Z]].to_numpy(float)
    same = (placed[CASE].to_numpy()[1:] == placed[CASE].to_numpy()[:-1]) & (
        placed[ROBOT].to_numpy()[1:] == placed[ROBOT].to_numpy()[:-1]
    )
    # a step between two positions of one robot in one run; the first of each path is 0
    steps = np.r_[0.0, np.where(same, np.sqrt((np.diff(xyz, axis=0) ** 2).sum(axis=1)), 0.0)]
    paths = placed.assign(_step=steps).groupby([CASE, ROBOT], sort=True)
    robots = paths.agg(
        distance=("_step", "sum"), x0=(X, "min"), x1=(X, "max"), y0=(Y, "min"), y1=(Y, "max")
    ).reset_index()
    robots["area"] = (robots["x1"] - robots["x0"]) * (robots["y1"] - robots["y0"])
    robots["_type"] = who(robots[ROBOT]).to_numpy()
    # a robot on its own only where its type has several in the batch: else it is its type
    kinds = robots.drop_duplicates(ROBOT)["_type"].value_counts()
    own = robots[robots["_type"].map(kinds).gt(1) & robots[ROBOT].ne(robots["_type"])]
    values = {}
    for measure, column in (("distance travelled", "distance"), ("region area", "area")):
        typed = robots.groupby(["_type", CASE], sort=True)[column].mean().reset_index()
        values[measure] = _long(
            [measure.split()[0]] * (len(typed) + len(own)),
            [*typed["_type"], *own[ROBOT]],
            [*typed[CASE], *own[CASE]],
            [*typed[column], *own[column]],
        )
    values["encounters"] = _encounter_counts(placed, who)
    return True, values


def _encounter_counts(placed: pd.DataFrame, who: Callable) -> pd.DataFrame:
    """Per run and pair of robot types, how many times two of their robots met; 0 in the
    runs where none did (a run with positions)."""
    runs = pd.Index(sorted(placed[CASE].unique()), name="run")
    met = encounters(placed)
    if met.empty:
        return _long([], [], [], [])
    kinds = np.sort(
        np.c_[who(met["robot"].astype(str)).to_numpy(str), who(met["other"]).to_numpy(str)],
        axis=1,
    )
    pairs = pd.Series([f"{a} and {b}" for a, b in kinds], index=met.index)
    counts = pd.crosstab(met[CASE].astype(str).to_numpy(), pairs.to_numpy())
    counts = counts.reindex(runs, fill_value=0).rename_axis(index="run", columns="who")
    table = counts.stack().rename("value").reset_index()
    return _long(["encounters"] * len(table), table["who"], table["run"], table["value"])


def _long(subject, who, run, value) -> pd.DataFrame:
    return pd.DataFrame(
        {
            "subject": np.asarray(subject, dtype=object),
            "who": np.asarray(who, dtype=object),
            "run": np.asarray(run, dtype=object),
            "value": np.asarray(value, dtype=float),
        }
    )


# -- the tests ---------------------------------------------------------------------------------


def per_run_values(first: Batch, second: Batch) -> pd.DataFrame:
    """Every value per run of both batches in one long table (``side`` 0 for A, 1 for B)."""
    return pd.concat([_values(first, second, 0), _values(second, first, 1)], ignore_index=True)


def _changes(long: pd.DataFrame, first: Batch, second: Batch) -> pd.DataFrame:
    table = mann_whitney(long)
    table["p_value"] = either(table["p_value"], welch(long).reindex(table.index))
    table = table.reset_index()
    table["q_value"] = benjamini_hochberg(table["p_value"])
    table["share"] = _shares(table, first, second)
    table["ranked"] = (table["q_value"].lt(ALPHA) & table["share"].ge(MIN_SHARE)).to_numpy(bool)
    table = table.sort_values("share", ascending=False, kind="stable", na_position="last")
    table = trusted_first(table.reset_index(drop=True)).drop(columns="rank")
    table["sentence"] = [change_sentence(row) for row in table.to_dict("records")]
    return table[COLUMNS]


def _values(part: Batch, other: Batch, side: int) -> pd.DataFrame:
    """Every value per run of ``part`` (``side`` 0 for A, 1 for B) in one long table."""
    count = len(part.runs)
    tables = [_long(["runs"] * count, [""] * count, part.runs.index, part.runs.to_numpy())]
    tables[0].insert(0, "measure", "run duration")
    for measure in MEASURES[1:-1]:
        values = part.values[measure]
        if measure in ("activity frequency", "transition frequency") or (
            measure == "encounters" and part.placed
        ):
            # a run without an activity did it 0 times, even when no run of its batch did it;
            # robots that never met in a run with positions met 0 times
            values = _with_zeros(values, other.values[measure], part.runs.index)
        tables.append(values.assign(measure=measure))
    tables.append(_variant_values(part, other))
    long = pd.concat(tables, ignore_index=True)
    return long.assign(side=side)


def _with_zeros(mine: pd.DataFrame, theirs: pd.DataFrame, runs: pd.Index) -> pd.DataFrame:
    missing = (
        theirs[["subject", "who"]]
        .drop_duplicates()
        .merge(mine[["subject", "who"]].drop_duplicates(), how="left", indicator=True)
    )
    missing = missing[missing["_merge"] == "left_only"].drop(columns="_merge")
    if missing.empty:
        return mine
    zeros = missing.merge(pd.DataFrame({"run": runs}), how="cross").assign(value=0.0)
    return pd.concat([mine, zeros], ignore_index=True)


def _variant_values(part: Batch, other: Batch) -> pd.DataFrame:
    """Whether each run follows each variant of two runs or more (in both batches), 1 or
    0."""
    counts = pd.concat([part.variants, other.variants]).value_counts()
    tested = counts[counts >= VARIANT_RUNS].index
    if not len(tested) or part.variants.empty:
        return _long([], [], [], []).assign(measure="variant share")
    follows = part.variants.to_numpy()[:, None] == tested.to_numpy()[None, :]
    return pd.DataFrame(
        {
            "measure": "variant share",
            "subject": np.tile(tested.astype(str), len(part.variants)),
            "who": "",
            "run": np.repeat(part.variants.index.to_numpy(), len(tested)),
            "value": follows.ravel().astype(float),
        }
    )


def mann_whitney(long: pd.DataFrame) -> pd.DataFrame:
    """Per measure, subject and robot (``who``): the runs and mean of A (``side`` 0) and of B
    (``side`` 1), the difference and the two-sided p-value of the Mann-Whitney U test of B
    against A (normal approximation with tie and continuity corrections, as in
    :mod:`robotale.enhancement.effects`; NaN when a side has no run or all values are equal).
    All keys at once: the ranks are taken within each key."""
    keys = ["measure", "subject", "who"]
    long = long.dropna(subset=["value"])
    grouped = long.groupby(keys, sort=False)
    ranks = grouped["value"].rank()
    n = grouped["value"].transform("size")
    # the tie term of each key: sum over its distinct values of t^3 - t
    tied = long.groupby([*keys, "value"], sort=False)["value"].transform("size").astype(float)
    frame = long.assign(
        _b=long["side"].eq(1).astype(float),
        _rank_b=ranks.where(long["side"].eq(1), 0.0),
        _a_value=long["value"].where(long["side"].eq(0)),
        _b_value=long["value"].where(long["side"].eq(1)),
        _tie=(tied**3 - tied) / tied,  # each of the t rows adds its 1/t share of t^3 - t
        _n=n,
    )
    table = frame.groupby(keys, sort=False).agg(
        runs_b=("_b", "sum"),
        runs=("_n", "first"),
        rank_b=("_rank_b", "sum"),
        ties=("_tie", "sum"),
        a=("_a_value", "mean"),
        b=("_b_value", "mean"),
    )
    n_b, n_all = table["runs_b"], table["runs"].astype(float)
    n_a = n_all - n_b
    u_b = table["rank_b"] - n_b * (n_b + 1) / 2
    u = np.maximum(u_b, n_a * n_b - u_b)
    tie_term = table["ties"] / (n_all * (n_all - 1)).where(n_all > 1)
    sigma = np.sqrt(n_a * n_b / 12 * ((n_all + 1) - tie_term))
    z = (u - n_a * n_b / 2 - 0.5) / sigma.where(sigma > 0)
    table["p_value"] = z.map(
        lambda x: min(1.0, math.erfc(x / math.sqrt(2))) if pd.notna(x) else math.nan
    )
    table["runs_a"], table["runs_b"] = n_a.astype(int), n_b.astype(int)
    table["difference"] = table["b"] - table["a"]
    table["relative"] = table["difference"] / table["a"].where(table["a"] != 0)
    return table[["runs_a", "runs_b", "a", "b", "difference", "relative", "p_value"]]


def welch(long: pd.DataFrame) -> pd.Series:
    """Per measure, subject and robot: the two-sided p-value of Welch's t-test of B's mean
    against A's (NaN with fewer than two runs on a side or no spread at all).

    The rank test misses a mean moved by a few runs (4 runs of 12 waiting 300 s move few
    ranks); the t-test on the same per-run values sees it. Welch's form, because a change
    usually changes the spread too, and with a dozen runs or more per side the mean is near
    normal enough for the t distribution."""
    # scipy.special alone: Student's t distribution function without the second that
    # importing scipy.stats costs (only comparisons need it)
    from scipy.special import stdtr

    keys = ["measure", "subject", "who"]
    long = long.dropna(subset=["value"])
    stats = long.groupby([*keys, "side"], sort=False)["value"].agg(["size", "mean", "var"])
    a = stats.xs(0, level="side")
    b = stats.xs(1, level="side").reindex(a.index)
    spread_a, spread_b = a["var"] / a["size"], b["var"] / b["size"]
    spread = spread_a + spread_b
    known = (a["size"] >= 2) & (b["size"] >= 2) & (spread > 0)
    t = (b["mean"] - a["mean"]) / np.sqrt(spread.where(known))
    df = spread**2 / (spread_a**2 / (a["size"] - 1) + spread_b**2 / (b["size"] - 1))
    # the upper tail beyond |t| is the distribution function below -|t|
    p = 2 * stdtr(df.where(known).to_numpy(float), -np.abs(t.to_numpy(float)))
    return pd.Series(p, index=a.index)


def either(rank_p: pd.Series, mean_p: pd.Series) -> pd.Series:
    """One p-value for "the ranks or the mean moved": the smaller of the two times the number
    of tests that could be made (Bonferroni over them, valid however they depend on each
    other), so the Benjamini-Hochberg procedure over all measures still bounds the false
    discoveries."""
    both = pd.concat([rank_p, mean_p], axis=1)
    made = both.notna().sum(axis=1)
    return (made * both.min(axis=1, skipna=True)).clip(upper=1.0).where(made > 0)


def benjamini_hochberg(p_values: pd.Series) -> pd.Series:
    """The Benjamini-Hochberg adjusted p-values (NaN where the p-value is; the others are
    the family)."""
    p = pd.to_numeric(p_values, errors="coerce")
    known = p.dropna().sort_values(kind="stable")
    m = len(known)
    if not m:
        return p
    scaled = known.to_numpy() * m / np.arange(1, m + 1)
    adjusted = np.minimum.accumulate(scaled[::-1])[::-1].clip(max=1.0)
    return pd.Series(adjusted, index=known.index).reindex(p.index)


def _shares(table: pd.DataFrame, first: Batch, second: Batch) -> pd.Series:
    """Each change on one scale (see the module's text)."""
    run_time = float(first.runs.mean()) if len(first.runs) else np.nan
    shares = table["relative"].abs()
    per_run = _occurrences_per_run(table, first, second)
    timed = table["measure"].isin(TIMED)
    seconds = table["difference"].abs() * per_run
    shares = shares.where(~timed, seconds / run_time)
    proportions = table["measure"].isin(("message loss", "variant share"))
    shares = shares.where(~proportions, table["difference"].abs())
    # robots that never met in A and meet in B: no relative change, a whole one
    new = table["measure"].eq("encounters") & table["a"].eq(0) & table["difference"].ne(0)
    return shares.where(~new, 1.0).astype(float)


def _occurrences_per_run(table: pd.DataFrame, first: Batch, second: Batch) -> pd.Series:
    """How many times per run a row's time counts: an activity's and a transition's times
    as often as B's runs (else A's) do them; a frequency's difference times the activity's
    mean duration or the transition's mean wait; a run's once."""
    frequency = {}
    durations = {}
    for part in (first, second):  # B's figures replace A's where both have them
        counts = part.values["activity frequency"]
        if not counts.empty:
            frequency.update(counts.groupby(["subject", "who"])["value"].mean().to_dict())
        timed = part.values["activity duration"]
        if not timed.empty:
            durations.update(timed.groupby(["subject", "who"])["value"].mean().to_dict())
    steps = {}
    waited = {}
    for part in (first, second):
        waits = part.values["transition wait"]
        if not waits.empty:
            per_run = waits.groupby(["subject", "who"])["run"].size() / max(len(part.runs), 1)
            steps.update(per_run.to_dict())
            waited.update(waits.groupby(["subject", "who"])["value"].mean().to_dict())
    times = []
    for row in table.to_dict("records"):
        key = (row["subject"], row["who"])
        times.append(
            {
                "activity duration": frequency.get(key, 1.0),
                "activity frequency": durations.get(key, 0.0),
                "transition wait": steps.get(key, 1.0),
                "transition frequency": waited.get(key, 0.0),
            }.get(row["measure"], 1.0)
        )
    return pd.Series(times, index=table.index, dtype=float)


# -- variants and bottlenecks ------------------------------------------------------------------


def variant_table(first: Batch, second: Batch) -> pd.DataFrame:
    """Per variant: the runs of A and of B that follow it, and whether it appeared or
    vanished."""
    a, b = first.variants.value_counts(), second.variants.value_counts()
    table = pd.DataFrame({"runs_a": a, "runs_b": b}).fillna(0).astype(int)
    table["share_a"] = table["runs_a"] / max(len(first.variants), 1)
    table["share_b"] = table["runs_b"] / max(len(second.variants), 1)
    table["status"] = np.select(
        [table["runs_a"].eq(0), table["runs_b"].eq(0)], ["appeared", "vanished"], "both"
    )
    table = table.rename_axis(VARIANT).reset_index()
    table["_runs"] = table["runs_a"] + table["runs_b"]
    return table.sort_values(["_runs", VARIANT], ascending=[False, True]).drop(columns="_runs")


def bottleneck_table(first: Batch, second: Batch) -> pd.DataFrame:
    """The first bottlenecks of each batch, side by side (rank in A, rank in B)."""
    ranks = []
    for part in (first, second):
        found = find_bottlenecks(part.analysis)
        table = found.table if found.has_data else pd.DataFrame()
        if table.empty:
            ranks.append(pd.DataFrame(columns=["kind", "activity", "robot", "rank"]))
            continue
        table = trusted_first(table)
        table = table[table["ranked"].astype(bool)] if "ranked" in table else table
        keep = table[["kind", "activity", "robot", "rank", "delay_per_case", "explanation"]]
        ranks.append(keep.assign(robot=keep["robot"].astype("string").fillna("")))
    merged = ranks[0].merge(
        ranks[1], on=["kind", "activity", "robot"], how="outer", suffixes=("_a", "_b")
    )
    return merged.sort_values(["rank_b", "rank_a"], na_position="last").reset_index(drop=True)


# -- sentences ---------------------------------------------------------------------------------


def _sentences(
    first: Batch,
    second: Batch,
    changes: pd.DataFrame,
    variants: pd.DataFrame,
    bottlenecks: pd.DataFrame,
) -> list[str]:
    """A change of robots first (it is the change itself, not a consequence); then the
    runs' duration with its cause when it changed, else the ranked changes before the
    sentence saying the runs did not; then variants, bottlenecks and how it was tested."""
    sentences = []
    robots = _robot_sentence(first, second)
    if robots:
        sentences.append(robots)
    others = changes[changes["ranked"] & changes["measure"].ne("run duration")]
    run, cause = _run_sentence(changes)
    if _run_row(changes)["ranked"]:
        sentences += [run, *others["sentence"][others.index != cause]]
    else:
        sentences += [*others["sentence"], run]
    sentences += _activity_sentences(first, second)
    sentences.append(_variant_sentence(variants, first, second))
    sentences.append(_bottleneck_sentence(bottlenecks, first.name, second.name))
    sentences.append(_spatial_sentence(first, second, changes))
    tested = int(changes["q_value"].notna().sum())
    sure = int((changes["q_value"] < ALPHA).sum())
    ranked = int(changes["ranked"].sum())
    sentences.append(
        f"{tested} differences were tested, run against run (Mann-Whitney U and Welch's t), "
        f"with the p-values adjusted for their number (Benjamini-Hochberg): {sure} with "
        f"p < {ALPHA:g}, "
        f"{ranked} of them also worth at least {MIN_SHARE:.0%} of a run."
    )
    return sentences


def _robot_sentence(first: Batch, second: Batch) -> str:
    gone = sorted(set(first.robots) - set(second.robots))
    new = sorted(set(second.robots) - set(first.robots))
    if not gone and not new:
        return ""
    parts = []
    if gone:
        parts.append(f"without {', '.join(gone)}")
    if new:
        parts.append(f"with {', '.join(new)} as well")
    return (
        f"{second.name} runs {' and '.join(parts)}: {len(second.robots)} robots against "
        f"{len(first.robots)}."
    )


def _run_row(changes: pd.DataFrame) -> dict:
    return changes[changes["measure"] == "run duration"].iloc[0].to_dict()


def _run_sentence(changes: pd.DataFrame) -> tuple[str, Any]:
    """How the runs' duration changed and, when it did, the largest change that goes the
    same way (its row's label, None without one)."""
    row = _run_row(changes)
    if not row["ranked"]:
        how = "longer" if row["difference"] > 0 else "shorter"
        return (
            f"Runs are not significantly {how}: {_pair(row['b'], row['a'])} (mean, "
            f"{_evidence(row['q_value'])}).",
            None,
        )
    # more often or longer both make a run longer: the sign of the difference is the way
    same_way = np.sign(changes["difference"]).eq(np.sign(row["difference"]))
    why = changes[changes["ranked"] & changes["measure"].isin(TIMED[1:]) & same_way]
    if why.empty:
        return change_sentence(row), None
    return f"{change_sentence(row).rstrip('.')}: {why.iloc[0]['sentence']}", why.index[0]


def change_sentence(row: dict) -> str:
    """One change in words, with its evidence."""
    measure, subject, who = row["measure"], row["subject"], row["who"]
    evidence = _evidence(row["q_value"])
    more = row["difference"] > 0
    percent = f"{abs(row['relative']):.0%}" if pd.notna(row["relative"]) else "infinitely"
    means = _pair(row["b"], row["a"], timed=measure in TIMED or measure == "message latency")
    owner = f"{who}'s " if who else ""
    if measure == "run duration":
        how = "longer" if more else "shorter"
        return f"Runs are {percent} {how} ({means} mean, {evidence})."
    if measure == "activity duration":
        how = "longer" if more else "less time"
        return f"{owner}{subject} takes {percent} {how} ({means} each, {evidence})."
    if measure == "activity frequency":
        doer = who or "The robots"
        return (
            f"{doer} {'does' if who else 'do'} {subject} {row['b']:.1f} times per run "
            f"instead of {row['a']:.1f} ({evidence})."
        )
    if measure == "transition wait":
        how = "longer" if more else "shorter"
        source, _, target = subject.partition(ARROW)
        return (
            f"{owner or 'The '}wait between {source} and {target} is {percent} {how} "
            f"({means}, {evidence})."
        )
    if measure == "transition frequency":
        source, _, target = subject.partition(ARROW)
        doer = who or "The robots"
        return (
            f"{doer} {'goes' if who else 'go'} from {source} to {target} {row['b']:.1f} times "
            f"per run instead of {row['a']:.1f} ({evidence})."
        )
    if measure == "message latency":
        how = "longer" if more else "less time"
        return f"{subject} messages take {percent} {how} to arrive ({means}, {evidence})."
    if measure == "message loss":
        return f"{row['b']:.0%} of {subject} messages are lost against {row['a']:.0%} ({evidence})."
    if measure == "message resends":
        return (
            f"{subject} messages are sent again {row['b']:.1f} times per run instead of "
            f"{row['a']:.1f} ({evidence})."
        )
    if measure == "battery used":
        how = "more" if more else "less"
        return (
            f"{who} uses {percent} {how} battery per run ({row['b']:.1f} against "
            f"{row['a']:.1f} percentage points, {evidence})."
        )
    if measure == "distance travelled":
        how = "farther" if more else "less far"
        return (
            f"{who} {'travels' if who else 'travel'} {percent} {how} per run ({row['b']:.1f} m "
            f"against {row['a']:.1f} m, {evidence})."
        )
    if measure == "region area":
        how = "larger" if more else "smaller"
        return (
            f"{owner}region (the x-y box of its positions per run) is {percent} {how} "
            f"({row['b']:.1f} m² against {row['a']:.1f} m², {evidence})."
        )
    if measure == "encounters":
        return (
            f"{who} robots meet {row['b']:.1f} times per run instead of {row['a']:.1f} "
            f"({evidence})."
        )
    return (
        f"{row['b']:.0%} of the runs follow the variant {_short(subject)} against "
        f"{row['a']:.0%} ({evidence})."
    )


def _activity_sentences(first: Batch, second: Batch) -> list[str]:
    """The activities (of a robot type) only one batch did, with the runs that did them."""
    done = [_done(part) for part in (first, second)]
    sentences = []
    for only, other, word in ((1, 0, "New in"), (0, 1, "Gone from")):
        keys = sorted(set(done[only]) - set(done[other]))
        if not keys:
            continue
        part = (first, second)[only]
        listed = ", ".join(
            f"{subject}" + (f" by {who}" if who else "") + f" (in {done[only][(subject, who)]} "
            f"of {len(part.runs)} runs of {part.name})"
            for subject, who in keys
        )
        sentences.append(f"{word} {second.name}: {listed}.")
    return sentences


def _done(part: Batch) -> dict[tuple[str, str], int]:
    """How many runs did each activity (per robot type)."""
    counts = part.values["activity frequency"]
    if counts.empty:
        return {}
    did = counts[counts["value"] > 0].groupby(["subject", "who"])["run"].nunique()
    return {key: int(n) for key, n in did.items()}


def _spatial_sentence(first: Batch, second: Batch, changes: pd.DataFrame) -> str:
    """Where the robots worked: which batch has no positions, else whether any spatial
    measure changed surely and largely (those changes are sentences of their own)."""
    unplaced = [part.name for part in (first, second) if not part.placed]
    if len(unplaced) == 2:
        return (
            f"Neither {first.name} nor {second.name} has positions, so where the robots "
            "worked is not compared."
        )
    if unplaced:
        return f"{unplaced[0]} has no positions, so where the robots worked is not compared."
    spatial = changes[changes["measure"].isin(SPATIAL)]
    moved, tested = int(spatial["ranked"].sum()), int(spatial["q_value"].notna().sum())
    if moved:
        return (
            f"Where the robots worked changed in {moved} of {tested} spatial measures tested "
            "(distance travelled, region area, encounters; above)."
        )
    return (
        "Where the robots worked did not change significantly (distance travelled, region "
        f"area and encounters per run, {tested} tested)."
    )


def _plural(number: int, noun: str) -> str:
    return f"{number} {noun}{'' if number == 1 else 's'}"


def _variant_sentence(variants: pd.DataFrame, first: Batch, second: Batch) -> str:
    new = variants[variants["status"] == "appeared"]
    gone = variants[variants["status"] == "vanished"]
    if new.empty and gone.empty:
        return f"The runs of {first.name} and {second.name} follow the same variants."
    return (
        f"{_plural(len(new), 'variant')} appeared ({int(new['runs_b'].sum())} of "
        f"{len(second.variants)} runs of {second.name} follow one), {len(gone)} vanished "
        f"({int(gone['runs_a'].sum())} of {len(first.variants)} runs of {first.name} "
        "followed one)."
    )


def _bottleneck_sentence(table: pd.DataFrame, a: str, b: str) -> str:
    firsts = [
        table.sort_values(f"rank_{side}").dropna(subset=[f"rank_{side}"]).head(1)
        for side in ("a", "b")
    ]
    if firsts[0].empty and firsts[1].empty:
        return f"Neither {a} nor {b} has a bottleneck that is both sure and large."
    words = [
        f"in {name}: {_bottleneck(first.iloc[0], side)}"
        if not first.empty
        else f"{name} has none that is both sure and large"
        for name, side, first in ((a, "a", firsts[0]), (b, "b", firsts[1]))
    ]
    same = not firsts[0].empty and not firsts[1].empty and firsts[0].index[0] == firsts[1].index[0]
    return ("The first bottleneck stays" if same else "The first bottleneck moved") + (
        f" ({words[0]}; {words[1]})."
    )


def _bottleneck(row: pd.Series, side: str) -> str:
    robot = f" by {row['robot']}" if row["robot"] else ""
    return (
        f"{row['kind']} at {row['activity']}{robot}, "
        f"{seconds_text(row[f'delay_per_case_{side}'])} per run"
    )


def _evidence(q_value: float) -> str:
    if pd.isna(q_value):
        return "untested"
    return "p < 0.001" if q_value < 0.001 else f"p = {q_value:.3f}"


def _pair(b: float, a: float, *, timed: bool = True) -> str:
    """B's value against A's, both in one unit (the one :func:`seconds_text` gives the
    larger)."""
    if not timed:
        return f"{b:.1f} against {a:.1f}"
    unit = seconds_text(np.nanmax([abs(a), abs(b)]))
    scale = {"s": 1.0, "min": 60.0, "h": 3600.0}[unit.rsplit(" ", 1)[-1].lstrip("0123456789.")]
    name = "s" if scale == 1.0 else f" {unit.rsplit(' ', 1)[-1]}"
    digits = 1
    return f"{b / scale:.{digits}f}{name} against {a / scale:.{digits}f}{name}"


def _short(variant: str, limit: int = 6) -> str:
    steps = variant.split(ARROW)
    shown = " → ".join(steps[:limit])
    return shown + (f" … ({len(steps)} activities)" if len(steps) > limit else "")
