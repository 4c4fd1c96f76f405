"""Bottlenecks: what makes cases slower, ranked by the seconds it adds per case.

Two sorts of candidate, one ranking (``delay_per_case``: how much longer, on average over all
cases, the cases take because of it):

Effects, measured by comparing the cases with a thing against the cases without it: an
activity of a robot (a class of the activity+robot model), a transition (a robot going from
one activity to the next), a rework loop (a robot doing an activity more than once in a case)
and a variant (a robot's whole path through a case; a case's path when several cases share
one). Its cost is the extra mean duration of the cases with it times the share of cases with
it. Nothing is special-cased by its name: an optional activity that only waits ranks high
because the cases with it take longer, and an activity found in every case, however long,
has no effect to measure. Candidates found in exactly the same cases are one row (the
simplest one named, the others in ``also``).

Steady costs, time that need not be there in any case that has it:

- waiting: the robot idles before the activity (its previous activity completed, this one has
  not started). Never its own duration, and not waiting to receive a message: the receiver is
  idle until another robot sends, and what holds the sender up shows among its own candidates;
- resource: the part of that wait during which another robot of the case was doing the same
  activity (queueing for a shared resource, such as one charging station);
- rework: the robot does the activity again right after doing it, for the same message if it
  is a message activity (a resend, a retry): the repeat and the wait before it;
- delay: the activity took longer than its fastest runs (the ``baseline_quantile`` of its
  durations, 10% by default);
- queueing: a message waited from its first send to its first receive.

Their cost is their excess summed over the cases and divided by the number of cases. For every
row ``longer_by`` / ``extra_median`` say how much longer (mean / median) the cases with it (for
a steady cost: the cases it hits hardest, above its median case) take than the others, and
``p_value`` how sure that is (Mann-Whitney U, see :mod:`robotale.enhancement.effects`).

A row is *ranked* (``ranked`` True) only with both a magnitude and a test: it adds at least
:data:`MIN_SHARE` of the runs' time (``share``) and its p-value is below :data:`ALPHA`. Every
ranked row comes before every other one (an effect that may be chance, one without a test
result, or one that adds under 1 % of a run), each part by delay per case. A step found in all
cases but one is "present" in every slow case, and without this its chance difference to that
one case would outrank a real cause; and 0 ms must never rank first.

The outcome is held fixed: when some runs did not complete (a robot's last activity in the run
never completed, or ended aborted or cancelled) and at least two did, only the completed runs
are compared, against each other; the aborted runs are left out and the summary says how many
(``aborted_runs_left_out``), so an escort found in every completed run is not "slower than the
others" because the others are the aborted ones.
"""

from __future__ import annotations

import numpy as np
import pandas as pd

from robotale.discovery.graph import format_seconds
from robotale.discovery.instances import DURATION, FINISHED, START_TIMESTAMP, interrupted
from robotale.enhancement.communication import TYPE, event_roles, shared_latencies
from robotale.enhancement.context import LogAnalysis, analysis_of, row_keys
from robotale.enhancement.effects import compare_cases
from robotale.enhancement.performance import (
    ARROW,
    VARIANT,
    WAIT,
    finished_instances,
    robot_steps,
    robot_times,
    shared_case_variants,
    shared_cases,
    shared_robot_times,
    shared_steps,
)
from robotale.enhancement.result import Figures, Perspective, focus_label, no_data
from robotale.eventlog.schema import ACTIVITY, CASE, RECEIVE, ROBOT, TIMESTAMP

#: effect candidates, simplest first (the one named when several share their cases)
EFFECTS = ("activity", "loop", "transition", "variant")
STEADY = ("waiting", "resource", "rework", "delay", "queueing")
KINDS = EFFECTS + STEADY
KEY = ["kind", "activity", "robot"]
#: an effect with a p-value at least this large may be chance: it is ranked after the others
ALPHA = 0.05
#: an effect that adds less than this share of the runs' time is ranked after the others
MIN_SHARE = 0.01


def find_bottlenecks(
    log: pd.DataFrame | LogAnalysis,
    *,
    activity: str | None = None,
    robot: str | None = None,
    baseline_quantile: float = 0.1,
    min_variant_cases: int = 2,
    top: int | None = None,
) -> Perspective:
    """Bottlenecks ranked by how much longer they make the cases (seconds per case), largest
    first; ``activity`` / ``robot`` keep the candidates of one activity or class. A variant is
    a candidate when at least ``min_variant_cases`` cases follow it."""
    analysis = analysis_of(log)
    instances = finished_instances(analysis)
    if instances.empty:
        return no_data("bottlenecks", "the log has no completed activity.")
    if ROBOT in instances.columns:
        steps, robots = shared_steps(analysis), shared_robot_times(analysis)
    else:
        instances = instances.assign(**{ROBOT: None})
        steps = robot_steps(instances)
        robots = robot_times(instances, steps)
    cases = shared_cases(analysis).set_index(CASE)["duration"]
    cases, left_out = _same_outcome(cases, run_outcomes(analysis))
    paths = _paths(robots, shared_case_variants(analysis))
    presence = _keep(_presence(instances, steps, paths, min_variant_cases), activity, robot)
    excess = _steady_excess(analysis, instances, steps, baseline_quantile)
    excess = _keep(excess, activity, robot)
    if left_out:
        presence = presence[presence[CASE].isin(cases.index)]
        excess = excess[excess[CASE].isin(cases.index)]
    parts = [_effect_rows(presence, cases), _steady_rows(excess, cases)]
    parts = [part for part in parts if not part.empty]
    ranking = pd.concat(parts) if parts else pd.DataFrame({"delay_per_case": []})
    if not (ranking["delay_per_case"] > 0).any():
        return no_data(
            "bottlenecks", f"nothing delays the cases of {focus_label(activity, robot)}."
        )
    ranking = _order(ranking[ranking["delay_per_case"] > 0], float(cases.sum()))
    if top is not None:
        ranking = ranking.head(top)
    first = ranking.iloc[0]
    return Perspective(
        name="bottlenecks",
        tables={"bottlenecks": ranking},
        figures=Figures({"bottlenecks": lambda: _figure(ranking)}),
        summary={
            "first": first["explanation"],
            "first_kind": first["kind"],
            "first_delay_per_case": float(first["delay_per_case"]),
            "candidates": len(ranking),
            "ranked": int(ranking["ranked"].sum()),
            "cases": len(cases),
            "aborted_runs_left_out": left_out,
            "compared": "completed runs against completed runs"
            if left_out
            else "all runs (every run completed)",
        },
    )


def run_outcomes(analysis: LogAnalysis) -> pd.Series:
    """Per run, whether it completed: no robot's last activity instance in it is unfinished
    or ended aborted or cancelled."""

    def build() -> pd.Series:
        instances = analysis.instances()
        if instances.empty:
            return pd.Series(dtype=bool)
        keys = [CASE, ROBOT] if ROBOT in instances.columns else [CASE]
        # instances come in start order: a robot's last is its last row in the run
        last = instances.drop_duplicates(keys, keep="last")
        failed = ~last[FINISHED].to_numpy(bool) | interrupted(last).to_numpy(bool)
        completed = pd.Series(~failed, index=last.index).groupby(last[CASE].to_numpy()).all()
        return completed

    return analysis.shared("run_outcomes", build)


def _same_outcome(cases: pd.Series, completed: pd.Series) -> tuple[pd.Series, int]:
    """The runs to compare: the completed ones when some did not complete and at least two
    did (else all), and how many were left out."""
    done = completed.reindex(cases.index).fillna(True).astype(bool)
    if done.all() or done.sum() < 2:
        return cases, 0
    return cases[done.to_numpy()], int((~done).sum())


def _keep(rows: pd.DataFrame, activity: str | None, robot: str | None) -> pd.DataFrame:
    if activity is not None:
        rows = rows[rows["activity"] == activity]
    if robot is not None:
        rows = rows[rows["robot"] == robot]
    return rows


# -- effects: the cases with a thing against the cases without it ----------------------------


def _paths(robots: pd.DataFrame, case_variants: pd.DataFrame) -> pd.DataFrame:
    """Rows of robot, case and variant: each robot's own path through a case and, when a case
    has several robots, the case's path (robot missing)."""
    paths = robots[[ROBOT, CASE, VARIANT]]
    if paths[CASE].duplicated().any():  # several robots: their own paths and the case's
        paths = pd.concat([paths, case_variants.assign(**{ROBOT: None})])
    return paths[[ROBOT, CASE, VARIANT]]


def _presence(
    instances: pd.DataFrame, steps: pd.DataFrame, paths: pd.DataFrame, min_variant_cases: int
) -> pd.DataFrame:
    """Rows of kind, activity, robot, case and occurrences: where each effect candidate is."""
    per_class = instances.groupby([ACTIVITY, ROBOT, CASE], dropna=False, sort=False).size()
    activities = _labelled(per_class, "activity")
    loops = _labelled(per_class[per_class > 1] - 1, "loop")
    moves = steps.groupby(["source", "target", ROBOT, CASE], dropna=False, sort=False).size()
    moves = moves.reset_index(name="occurrences")
    transitions = pd.DataFrame(
        {
            "kind": "transition",
            "activity": moves["source"].astype(str) + ARROW + moves["target"].astype(str),
            "robot": moves[ROBOT],
            CASE: moves[CASE],
            "occurrences": moves["occurrences"],
        }
    )
    common = paths.groupby([VARIANT, ROBOT], dropna=False)[CASE].transform("size")
    paths = paths[common >= min_variant_cases]
    variants = pd.DataFrame(
        {
            "kind": "variant",
            "activity": paths[VARIANT],
            "robot": paths[ROBOT],
            CASE: paths[CASE],
            "occurrences": 1,
        }
    )
    return pd.concat([activities, loops, transitions, variants], ignore_index=True)


def _labelled(counts: pd.Series, kind: str) -> pd.DataFrame:
    table = counts.reset_index(name="occurrences").rename(columns={ACTIVITY: "activity"})
    return table.rename(columns={ROBOT: "robot"}).assign(kind=kind)


def _effect_rows(presence: pd.DataFrame, cases: pd.Series) -> pd.DataFrame:
    if presence.empty:
        return pd.DataFrame()
    presence = presence.assign(_id=presence.groupby(KEY, dropna=False, sort=False).ngroup())
    stats = compare_cases(presence, "_id", cases)
    stats = stats[(stats["cases_without"] > 0) & (stats["extra_mean"] > 0)]
    if stats.empty:
        return pd.DataFrame()
    chosen = presence[presence["_id"].isin(stats.index)]
    names = chosen.groupby("_id")[KEY].first()
    table = names.join(stats).join(chosen.groupby("_id")["occurrences"].sum())
    table = table.join(_same_cases(chosen, table))
    table = table[table["_keep"]].drop(columns="_keep")
    table["cases"] = table["cases_with"]
    table["total"] = table["extra_mean"] * table["cases_with"]
    table["mean"] = table["extra_mean"]
    table["delay_per_case"] = table["total"] / len(cases)
    return table.reset_index(drop=True)


def _same_cases(chosen: pd.DataFrame, table: pd.DataFrame) -> pd.DataFrame:
    """Candidates found in exactly the same cases are one: the simplest kind (then the shortest
    name) is kept, and names the others in ``also``."""
    signature = _case_set_ids(chosen)
    order = table.assign(
        _sig=signature,
        _kind=table["kind"].map(EFFECTS.index),
        _len=table["activity"].astype(str).str.len(),
    ).sort_values(["_sig", "_kind", "_len"], kind="stable")
    first = ~order["_sig"].duplicated()
    robots = order["robot"].map(lambda r: f" ({r})" if isinstance(r, str) else "")
    label = order["kind"] + " " + order["activity"].astype(str) + robots
    others = label[~first].groupby(order.loc[~first, "_sig"]).agg("; ".join)
    also = order["_sig"].map(others).where(first)
    return pd.DataFrame({"_keep": first, "also": also}).reindex(table.index)


def _case_set_ids(chosen: pd.DataFrame) -> pd.Series:
    """Per ``_id``, a number shared by exactly the ids found in the same cases: each case gets
    two random 64-bit tags, and a set is known by its size and the (wrapping) sums of its
    cases' tags, a collision being as likely as guessing 128 random bits."""
    codes, _ = pd.factorize(chosen[CASE])
    tags = np.random.default_rng(0).integers(0, 2**63, size=(codes.max() + 2, 2), dtype=np.uint64)
    mine = tags[codes]  # a missing case (code -1) takes the last row, its own tag
    sums = pd.DataFrame({"a": mine[:, 0], "b": mine[:, 1]}).groupby(chosen["_id"].to_numpy())
    signature = sums.sum().assign(n=sums.size())
    return signature.groupby(["n", "a", "b"], sort=False).ngroup()


# -- steady costs: time that need not be there --------------------------------------------------


def _steady_excess(
    analysis: LogAnalysis, instances: pd.DataFrame, steps: pd.DataFrame, baseline_quantile: float
) -> pd.DataFrame:
    waiting, resource = _waiting(steps, instances, _receive_activities(instances))
    parts = [
        waiting,
        resource,
        _rework(steps, instances),
        _delays(instances, baseline_quantile),
        _queueing(analysis),
    ]
    parts = [part for part in parts if not part.empty]
    if not parts:
        return pd.DataFrame(columns=[*KEY, CASE, "excess"])
    excess = pd.concat(parts)
    return excess[excess["excess"] > 0]


def _receive_activities(instances: pd.DataFrame) -> set[str]:
    return set(instances.loc[event_roles(instances) == RECEIVE, ACTIVITY].unique())


def _repeats(steps: pd.DataFrame) -> pd.Series:
    """Steps that do the same thing again: same activity and, if any, the same message."""
    same = steps["source"] == steps["target"]
    if "source_msg_id" in steps.columns:
        source, target = steps["source_msg_id"], steps["target_msg_id"]
        same &= (source == target).fillna(False) | (source.isna() & target.isna())
    return same.astype(bool)


def _waiting(steps: pd.DataFrame, instances: pd.DataFrame, receives: set[str]):
    """Idle time before an activity, split into plain waiting and queueing for a resource."""
    waits = steps[~_repeats(steps) & ~steps["target"].isin(receives) & (steps[WAIT] > 0)]
    queued = _resource_overlap(waits, instances)
    return (
        _excess_rows(waits, "waiting", waits["target"], waits[WAIT] - queued),
        _excess_rows(waits, "resource", waits["target"], queued),
    )


def _resource_overlap(waits: pd.DataFrame, instances: pd.DataFrame) -> pd.Series:
    """Per wait, the seconds during which another robot of the case did the activity waited
    for. The waiting robot runs nothing while it waits, so the time the activity was busy at
    all (the union of its instances in the case) during the wait is the queueing."""
    shared = instances.groupby([CASE, ACTIVITY], dropna=False)[ROBOT].transform("nunique") > 1
    busy = instances.loc[shared, [CASE, ACTIVITY, START_TIMESTAMP, TIMESTAMP]]
    if busy.empty or waits.empty:
        return pd.Series(0.0, index=waits.index)
    origin = busy[START_TIMESTAMP].min()
    busy_group, wait_group = _group_numbers(
        [busy[CASE], busy[ACTIVITY]], [waits[CASE], waits["target"]]
    )
    span = float((busy[TIMESTAMP].max() - origin).total_seconds()) + 1.0
    starts, lengths, cumulative = _busy_union(
        busy_group, _seconds(busy[START_TIMESTAMP], origin), _seconds(busy[TIMESTAMP], origin), span
    )
    known = wait_group >= 0
    offset = wait_group[known] * span

    def busy_until(times: pd.Series) -> np.ndarray:
        at = _seconds(times[known], origin) + offset
        k = np.searchsorted(starts, at, side="right") - 1
        inside = np.clip(at - starts[np.maximum(k, 0)], 0, lengths[np.maximum(k, 0)])
        return np.where(k >= 0, cumulative[np.maximum(k, 0)] + inside, 0.0)

    overlap = np.zeros(len(waits))
    overlap[known] = busy_until(waits["target_start"]) - busy_until(waits["source_end"])
    return pd.Series(np.minimum(overlap, waits[WAIT].to_numpy()), index=waits.index)


def _group_numbers(busy: list[pd.Series], waits: list[pd.Series]) -> tuple[np.ndarray, np.ndarray]:
    """Numbers for the (case, activity) pairs of ``busy``, in order of first appearance, and
    the number of each wait's pair (-1 when nothing was busy with it); values compare as text,
    as a missing case matches a missing case."""
    joint_busy = np.zeros(len(busy[0]), dtype=np.int64)
    joint_waits = np.zeros(len(waits[0]), dtype=np.int64)
    for mine, theirs in zip(busy, waits, strict=True):
        both = np.concatenate(
            [mine.astype(str).to_numpy(object), theirs.astype(str).to_numpy(object)]
        )
        codes, uniques = pd.factorize(both)
        joint_busy = joint_busy * len(uniques) + codes[: len(mine)]
        joint_waits = joint_waits * len(uniques) + codes[len(mine) :]
    busy_group, pairs = pd.factorize(joint_busy)
    return busy_group, pd.Index(pairs).get_indexer(joint_waits)


def _seconds(times: pd.Series, origin: pd.Timestamp) -> np.ndarray:
    return (times - origin).dt.total_seconds().to_numpy(float)


def _busy_union(group: np.ndarray, begin: np.ndarray, end: np.ndarray, span: float):
    """The union of each group's intervals on one axis (group g shifted by g * span): sorted
    starts, lengths, and the busy time before each (a running total across groups)."""
    begin, end = begin + group * span, end + group * span
    order = np.argsort(begin, kind="stable")
    begin, end = begin[order], end[order]
    reach = np.maximum.accumulate(end)
    new = np.ones(len(begin), dtype=bool)
    new[1:] = begin[1:] > reach[:-1]
    block = np.cumsum(new) - 1
    starts = begin[new]
    stops = pd.Series(end).groupby(block).max().to_numpy()
    lengths = stops - starts
    cumulative = np.concatenate([[0.0], np.cumsum(lengths)[:-1]])
    return starts, lengths, cumulative


def _rework(steps: pd.DataFrame, instances: pd.DataFrame) -> pd.DataFrame:
    repeats = steps[_repeats(steps)]
    # the repeated instance: the one that starts at this step's target start
    columns = [instances[c] for c in (CASE, ROBOT, ACTIVITY, START_TIMESTAMP)]
    wanted = [repeats[c] for c in (CASE, ROBOT, "target", "target_start")]
    keys = row_keys(columns, wanted)
    if keys is None:  # a missing value: matched as the index of tuples matches it
        durations = instances.set_index([CASE, ROBOT, ACTIVITY, START_TIMESTAMP])[DURATION]
        at = pd.MultiIndex.from_arrays(wanted)
    else:
        durations, at = pd.Series(instances[DURATION].to_numpy(), index=keys[0]), keys[1]
    durations = durations[~durations.index.duplicated()]
    repeat_time = durations.reindex(at).fillna(0).to_numpy()
    return _excess_rows(repeats, "rework", repeats["target"], repeats[WAIT] + repeat_time)


def _delays(instances: pd.DataFrame, quantile: float) -> pd.DataFrame:
    keys = [ACTIVITY, ROBOT]
    baseline = instances.groupby(keys, dropna=False)[DURATION].transform("quantile", quantile)
    over = (instances[DURATION] - baseline).clip(lower=0)
    return _excess_rows(instances, "delay", instances[ACTIVITY], over)


def _queueing(analysis: LogAnalysis) -> pd.DataFrame:
    messages = shared_latencies(analysis)
    if messages.empty or CASE not in messages.columns:
        return pd.DataFrame()
    latency = messages["latency"].fillna(0)
    return _excess_rows(
        messages.rename(columns={"sender": ROBOT}), "queueing", messages[TYPE], latency
    )


def _excess_rows(rows: pd.DataFrame, kind: str, activity: pd.Series, excess: pd.Series):
    # the columns' own arrays: turning text columns into Python objects costs more than the rest
    return pd.DataFrame(
        {
            "kind": kind,
            "activity": activity.array,
            "robot": rows[ROBOT].array,
            CASE: rows[CASE].array,
            "excess": np.asarray(excess, dtype=float),
        }
    )


def _steady_rows(excess: pd.DataFrame, cases: pd.Series) -> pd.DataFrame:
    if excess.empty:
        return pd.DataFrame()
    excess = excess.assign(_id=excess.groupby(KEY, dropna=False, sort=False).ngroup())
    grouped = excess.groupby("_id")
    table = (
        grouped[KEY]
        .first()
        .join(
            grouped.agg(
                occurrences=("excess", "size"),
                cases=(CASE, "nunique"),
                total=("excess", "sum"),
                mean=("excess", "mean"),
            )
        )
    )
    table["delay_per_case"] = table["total"] / len(cases)
    stats = compare_cases(_hardest_hit(excess, cases), "_id", cases)
    table = table.join(stats[["cases_without", "extra_mean", "extra_median", "p_value"]])
    return table.reset_index(drop=True)


def _hardest_hit(excess: pd.DataFrame, cases: pd.Series) -> pd.DataFrame:
    """Per steady candidate, the cases whose excess is above its median case's (cases without
    any of it counting as 0): the cases it hits hardest."""
    case_code, case_names = pd.factorize(excess[CASE])
    known = case_code >= 0  # a row without a case belongs to no case
    ids, case_code = excess["_id"].to_numpy()[known], case_code[known]
    # one integer per candidate and case: grouping by it avoids hashing the case names again
    pair = pd.Series(ids.astype(np.int64) * len(case_names) + case_code)
    per_case = pd.Series(excess["excess"].to_numpy(float)[known]).groupby(pair, sort=False).sum()
    pairs = pair.drop_duplicates()  # in the order of per_case's groups
    per_id = ids[pairs.index.to_numpy()]
    medians = _medians_with_zeros(per_id, per_case.to_numpy(), len(cases))
    above = per_case.to_numpy() > medians.reindex(per_id).to_numpy()
    cases_of = np.asarray(case_names.take(pairs.to_numpy() % max(len(case_names), 1)))
    return pd.DataFrame({"_id": per_id[above], CASE: cases_of[above]})


def _medians_with_zeros(ids: np.ndarray, values: np.ndarray, width: int) -> pd.Series:
    """Per id, the median of its values padded with zeros to ``width`` values, for all
    candidates at once: in the padded sorted values, its negative values come first, then the
    zeros, then the rest."""
    frame = pd.DataFrame({"_id": ids, "v": values})
    frame = frame.sort_values(["_id", "v"], kind="stable")
    size = frame.groupby("_id", sort=True).size()
    negative = (frame["v"] < 0).groupby(frame["_id"], sort=True).sum().to_numpy()
    start = np.concatenate([[0], np.cumsum(size.to_numpy())[:-1]])
    count = size.to_numpy()
    zeros = np.maximum(width - count, 0)
    total = count + zeros
    values = frame["v"].to_numpy()

    def kth(k: np.ndarray) -> np.ndarray:
        from_values = np.where(k < negative, k, k - zeros)  # among the group's own values
        inside = (k >= negative) & (k < negative + zeros)
        safe = np.clip(start + from_values, 0, max(len(values) - 1, 0))
        return np.where(inside, 0.0, values[safe])

    medians = (kth((total - 1) // 2) + kth(total // 2)) / 2
    return pd.Series(medians, index=size.index)


# -- the ranking -------------------------------------------------------------------------------


def _order(ranking: pd.DataFrame, total_time: float) -> pd.DataFrame:
    share = ranking["total"] / (total_time or float("nan"))
    tested = pd.to_numeric(ranking["p_value"], errors="coerce").lt(ALPHA)
    ranking = ranking.assign(
        share=share,
        longer_by=ranking["extra_mean"],
        _kind=ranking["kind"].map(KINDS.index),
        ranked=(tested & share.ge(MIN_SHARE)).to_numpy(bool),
    )
    ranking = ranking.sort_values(
        ["ranked", "delay_per_case", "_kind", "occurrences"],
        ascending=[False, False, True, False],
        kind="stable",
    ).reset_index(drop=True)
    ranking.insert(0, "rank", range(1, len(ranking) + 1))
    ranking["explanation"] = [_explain(row) for row in ranking.to_dict("records")]
    if "also" not in ranking.columns:
        ranking["also"] = None
    columns = [
        "rank",
        *KEY,
        "occurrences",
        "cases",
        "cases_without",
        "total",
        "mean",
        "delay_per_case",
        "share",
        "longer_by",
        "extra_median",
        "p_value",
        "ranked",
        "also",
        "explanation",
    ]
    return ranking[columns]


def _explain(row: dict) -> str:
    who = row["robot"] if isinstance(row["robot"], str) else "the robot"
    each = format_seconds(row["mean"])
    per_case = format_seconds(row["delay_per_case"])
    times = "once" if row["occurrences"] == 1 else f"{row['occurrences']} times"
    name = _short(str(row["activity"]))
    if row["kind"] in EFFECTS:
        whose = f"{row['robot']}'s" if isinstance(row["robot"], str) else "the"
        subject = {
            "activity": f"cases with {name} by {who}",
            "loop": f"cases where {who} repeats {name}",
            "transition": f"cases where {who} goes {name}",
            "variant": f"cases where {whose} path is {name}",
        }[row["kind"]]
        sentence = (
            f"{subject} take {each} longer than the others "
            f"({row['cases']} of {int(row['cases'] + row['cases_without'])} cases)"
        )
    else:
        sentence = {
            "waiting": f"{who} waits {each} on average before {name} ({times})",
            "resource": f"{who} queues {each} for {name} while another robot does it ({times})",
            "rework": f"{who} repeats {name} {times}, {each} each",
            "delay": f"{name} by {who} runs {each} longer than its fastest runs ({times})",
            "queueing": f"{name} messages wait {each} from send to receipt ({times})",
        }[row["kind"]]
    return f"{sentence}: {per_case} per case ({_how_sure(row)})"


def _how_sure(row: dict) -> str:
    """The magnitude as a share of the runs' time, and the test: why a row ranks or not."""
    share = row["share"]
    size = "under 1% of a run" if not share >= MIN_SHARE else f"{share:.0%} of the runs' time"
    if pd.isna(row["p_value"]):
        return f"{size}; no test possible: may be chance"
    verdict = "may be chance" if row["p_value"] >= ALPHA else "unlikely to be chance"
    return f"{size}; p = {row['p_value']:.2g}, {verdict}"


def _short(text: str, limit: int = 80) -> str:
    return text if len(text) <= limit else text[: limit - 3] + "..."


def _shown(ranking: pd.DataFrame) -> pd.DataFrame:
    """The first 15 candidates, each with its bar's label: kind, activity and robot."""
    return ranking.head(15).assign(
        candidate=lambda t: (
            t["kind"]
            + ": "
            + t["activity"].astype(str).map(lambda a: _short(a, 40))
            + " ("
            + t["robot"].fillna("-").astype(str)
            + ")"
        )
    )


def _figure(ranking: pd.DataFrame):
    """The first 15 candidates as horizontal bars, one trace per kind: the figure
    ``px.bar(shown, x="delay_per_case", y="candidate", color="kind", orientation="h",
    hover_data=["explanation"])`` draws, built from graph objects (plotly express spent
    about 0.03 s of a cold Perspectives page's first answer working out what to draw)."""
    # plotly takes about half a second to import: only a figure needs it
    import plotly.graph_objects as go
    import plotly.io as pio

    shown = _shown(ranking)
    template = pio.templates[pio.templates.default]
    colours = template.layout.colorway
    bars = [
        _kind_bars(str(kind), rows, colours[number % len(colours)])
        for number, (kind, rows) in enumerate(shown.groupby("kind", sort=False))
    ]
    # in plotly express's order of setting them, so that the JSON is the same text as its
    axes = {
        "xaxis": {"anchor": "y", "domain": [0.0, 1.0]},
        "yaxis": {"anchor": "x", "domain": [0.0, 1.0]},
    }
    labels = {
        "xaxis": {"title": {"text": "delay_per_case"}},
        "yaxis": {"title": {"text": "candidate"}},
        "legend": {"title": {"text": "kind"}, "tracegroupgap": 0},
        "title": {"text": "Bottlenecks: seconds they add per case"},
        "barmode": "relative",
    }
    figure = go.Figure().update_layout(axes).add_traces(bars).update_layout(labels)
    figure.update_layout(template=template, overwrite=True)
    return figure.update_yaxes(autorange="reversed")


def _kind_bars(kind: str, rows: pd.DataFrame, colour: str):
    """One kind's bars, with the hover text and legend entry plotly express gives them."""
    import plotly.graph_objects as go  # imported by the figure first (plotly's start-up cost)

    return go.Bar(
        customdata=rows[["explanation"]].to_numpy(object),
        hovertemplate=(
            f"kind={kind}<br>delay_per_case=%{{x}}<br>candidate=%{{y}}"
            "<br>explanation=%{customdata[0]}<extra></extra>"
        ),
        legendgroup=kind,
        marker={"color": colour, "pattern": {"shape": ""}},
        name=kind,
        orientation="h",
        showlegend=True,
        textposition="auto",
        x=rows["delay_per_case"].to_numpy(),
        xaxis="x",
        y=rows["candidate"].to_numpy(object),
        yaxis="y",
    )
