"""Bottlenecks: what makes cases slower than they need to be, ranked by the time it costs them.

Long work is not a bottleneck when it always takes as long as it must; what costs time is the
part that need not be there. Each candidate is an activity of a robot (a class of the
activity+robot model), with its excess time per occurrence:

- waiting: the robot idles before the activity (its previous activity completed, this one has
  not started); no wait is needed, so all of it is excess. Waiting to receive a message is
  not counted: the receiver is idle until another robot sends, and what holds the sender up
  shows among the sender's own candidates (and the message's queueing);
- rework: the robot does the activity again right after doing it, for the same message if it
  is a message activity (a resend, a retry): the repeat and the wait before it are excess;
- delay: the activity took longer than it can take, i.e. than its fastest runs (the
  ``baseline_quantile`` of its durations, 10% by default);
- queueing: a message waited from its first send to its first receive.

A candidate's cost is its excess summed over the cases and divided by the number of cases:
how much longer, on average, the cases take because of it (candidates may overlap: a resent
message is rework for its sender and queueing for the message). The table also gives how much
longer the cases in which it happens take than the others (``longer_by``) when both exist.
"""

from __future__ import annotations

import pandas as pd

from robotale.discovery.graph import format_seconds
from robotale.discovery.instances import DURATION
from robotale.enhancement.communication import TYPE, message_table
from robotale.enhancement.performance import WAIT, case_durations, finished_instances, robot_steps
from robotale.enhancement.result import Perspective, focus_label, no_data
from robotale.eventlog.schema import ACTIVITY, CASE, RECEIVE, ROBOT, message_roles

KINDS = ("waiting", "rework", "delay", "queueing")


def find_bottlenecks(
    log: pd.DataFrame,
    *,
    activity: str | None = None,
    robot: str | None = None,
    baseline_quantile: float = 0.1,
    top: int | None = None,
) -> Perspective:
    """Bottlenecks ranked by how much longer they make the cases (seconds per case), largest
    first; ``activity`` / ``robot`` keep the candidates of one activity or class."""
    instances = finished_instances(log)
    if instances.empty:
        return no_data("bottlenecks", "the log has no completed activity.")
    if ROBOT not in instances.columns:
        instances = instances.assign(**{ROBOT: None})
    steps = robot_steps(instances)
    excess = pd.concat(
        [
            _waiting(steps, _receive_activities(instances)),
            _rework(steps, instances),
            _delays(instances, baseline_quantile),
            _queueing(log),
        ]
    )
    excess = excess[excess["excess"] > 0]
    if activity is not None:
        excess = excess[excess["activity"] == activity]
    if robot is not None:
        excess = excess[excess["robot"] == robot]
    if excess.empty:
        return no_data(
            "bottlenecks", f"nothing delays the cases of {focus_label(activity, robot)}."
        )
    ranking = _rank(excess, case_durations(instances))
    if top is not None:
        ranking = ranking.head(top)
    return Perspective(
        name="bottlenecks",
        tables={"bottlenecks": ranking},
        figures={"bottlenecks": _figure(ranking)},
        summary={"first": ranking.iloc[0]["explanation"], "candidates": len(ranking)},
    )


def _receive_activities(instances: pd.DataFrame) -> set[str]:
    return set(instances.loc[message_roles(instances) == RECEIVE, ACTIVITY])


def _repeats(steps: pd.DataFrame) -> pd.Series:
    """Steps that do the same thing again: same activity and, if any, the same message."""
    same = steps["source"] == steps["target"]
    if "source_msg_id" in steps.columns:
        source, target = steps["source_msg_id"], steps["target_msg_id"]
        same &= (source == target).fillna(False) | (source.isna() & target.isna())
    return same.astype(bool)


def _waiting(steps: pd.DataFrame, receives: set[str]) -> pd.DataFrame:
    waits = steps[~_repeats(steps) & ~steps["target"].isin(receives)]
    return _excess_rows(waits, "waiting", waits["target"], waits[WAIT])


def _rework(steps: pd.DataFrame, instances: pd.DataFrame) -> pd.DataFrame:
    repeats = steps[_repeats(steps)]
    # the repeated instance: the one that starts at this step's target start
    durations = instances.set_index([CASE, ROBOT, ACTIVITY, "start_timestamp"])[DURATION]
    durations = durations[~durations.index.duplicated()]
    keys = pd.MultiIndex.from_arrays(
        [
            repeats[CASE],
            repeats[ROBOT],
            repeats["target"],
            repeats["target_start"],
        ]
    )
    repeat_time = durations.reindex(keys).fillna(0).to_numpy()
    return _excess_rows(repeats, "rework", repeats["target"], repeats[WAIT] + repeat_time)


def _delays(instances: pd.DataFrame, quantile: float) -> pd.DataFrame:
    keys = [ACTIVITY, ROBOT]
    baseline = instances.groupby(keys, dropna=False)[DURATION].transform("quantile", quantile)
    over = (instances[DURATION] - baseline).clip(lower=0)
    return _excess_rows(instances, "delay", instances[ACTIVITY], over)


def _queueing(log: pd.DataFrame) -> pd.DataFrame:
    messages = message_table(log)
    if messages.empty or CASE not in messages.columns:
        return pd.DataFrame()
    latency = messages["latency"].fillna(0)
    return _excess_rows(
        messages.rename(columns={"sender": ROBOT}), "queueing", messages[TYPE], latency
    )


def _excess_rows(rows: pd.DataFrame, kind: str, activity: pd.Series, excess: pd.Series):
    return pd.DataFrame(
        {
            "kind": kind,
            "activity": activity.to_numpy(),
            "robot": rows[ROBOT].to_numpy(),
            CASE: rows[CASE].to_numpy(),
            "excess": excess.to_numpy(dtype=float),
        }
    )


def _rank(excess: pd.DataFrame, cases: pd.DataFrame) -> pd.DataFrame:
    n_cases = len(cases)
    total_time = float(cases["duration"].sum()) or float("nan")
    grouped = excess.groupby(["kind", "activity", "robot"], dropna=False, sort=False)
    table = grouped.agg(
        occurrences=("excess", "size"),
        cases=(CASE, "nunique"),
        total=("excess", "sum"),
        mean=("excess", "mean"),
    ).reset_index()
    table["delay_per_case"] = table["total"] / n_cases
    table["share"] = table["total"] / total_time
    table["longer_by"] = _longer_by(excess, cases, table[["kind", "activity", "robot"]])
    table = table.sort_values(["delay_per_case", "occurrences"], ascending=[False, False])
    table = table.reset_index(drop=True)
    table.insert(0, "rank", range(1, len(table) + 1))
    table["explanation"] = table.apply(_explain, axis=1)
    return table


def _longer_by(excess: pd.DataFrame, cases: pd.DataFrame, candidates: pd.DataFrame) -> list:
    """Per candidate, how much longer the cases it hits hardest (excess above the median
    case's) take than the others; ``None`` when it costs every case the same."""
    keys = ["kind", "activity", "robot"]
    labelled = excess.assign(robot=excess["robot"].fillna("\x00"))
    per_case = labelled.pivot_table(
        index=keys, columns=CASE, values="excess", aggfunc="sum", fill_value=0.0
    ).reindex(columns=cases[CASE], fill_value=0.0)
    durations = cases["duration"].to_numpy()
    hit = per_case.to_numpy() > per_case.median(axis=1).to_numpy()[:, None]
    results = {}
    for key, row in zip(per_case.index, hit, strict=True):
        results[key] = float(durations[row].mean() - durations[~row].mean()) if row.any() else None
    lookup = candidates.assign(robot=candidates["robot"].fillna("\x00"))
    return [results[tuple(key)] for key in lookup.itertuples(index=False, name=None)]


def _explain(row: pd.Series) -> str:
    who = row["robot"] if isinstance(row["robot"], str) else "the robot"
    each = format_seconds(row["mean"])
    per_case = format_seconds(row["delay_per_case"])
    times = "once" if row["occurrences"] == 1 else f"{row['occurrences']} times"
    sentences = {
        "waiting": f"{who} waits {each} on average before {row['activity']} ({times})",
        "rework": f"{who} repeats {row['activity']} {times}, {each} each",
        "delay": f"{row['activity']} by {who} runs {each} longer than its fastest runs ({times})",
        "queueing": f"{row['activity']} messages wait {each} from send to receipt ({times})",
    }
    return f"{sentences[row['kind']]}: {per_case} per case"


def _figure(ranking: pd.DataFrame):
    import plotly.express as px

    shown = ranking.head(15).assign(
        candidate=lambda t: t["kind"] + ": " + t["activity"] + " (" + t["robot"].fillna("-") + ")"
    )
    return px.bar(
        shown,
        x="delay_per_case",
        y="candidate",
        color="kind",
        orientation="h",
        hover_data=["explanation"],
        title="Bottlenecks: seconds they add per case",
    ).update_yaxes(autorange="reversed")
