"""Performance: activity durations, waiting between activities, slowest transitions, cases.

Durations are those of activity instances (a start paired with its completion). Waiting is
measured per robot: the time before one of its activities starts during which the robot had
no activity running (its previous activities had all completed). A robot running a long
activity while others come and go, such as a drone exploring while it reports weeds, is not
waiting; and a robot waits for its own next step, not for another robot's.
"""

from __future__ import annotations

import pandas as pd

from robotale.discovery.instances import DURATION, FINISHED, START_TIMESTAMP, activity_instances
from robotale.enhancement.result import Perspective, focus_label, no_data
from robotale.eventlog.schema import ACTIVITY, CASE, MSG_ID, ROBOT, TIMESTAMP

WAIT = "wait"


def performance_perspective(
    log: pd.DataFrame, *, activity: str | None = None, robot: str | None = None
) -> Perspective:
    """Activity durations, waiting per transition (slowest first) and case durations.

    With ``activity`` and/or ``robot``: that activity's (class's) durations, the transitions
    into and out of it and the cases it occurs in.
    """
    instances = finished_instances(log)
    if instances.empty:
        return no_data("performance", "the log has no completed activity.")
    steps = robot_steps(instances)
    cases = case_durations(instances)
    chosen = _focus(instances, activity, robot)
    if chosen.empty:
        return no_data("performance", f"no instance of {focus_label(activity, robot)}.")
    if activity is not None or robot is not None:
        steps = steps[_touches(steps, activity, robot)]
        cases = cases[cases[CASE].isin(chosen[CASE])]
    durations = activity_durations(chosen)
    waiting = transition_waits(steps)
    return Perspective(
        name="performance",
        tables={"activities": durations, "waiting": waiting, "cases": cases},
        figures={
            "durations": _durations_figure(chosen),
            "waiting": _waiting_figure(waiting),
            "cases": _cases_figure(cases),
        },
        summary={
            "cases": len(cases),
            "case_duration_mean": float(cases["duration"].mean()),
            "slowest_transition": None if waiting.empty else _transition_name(waiting.iloc[0]),
        },
    )


def finished_instances(log: pd.DataFrame) -> pd.DataFrame:
    instances = activity_instances(log)
    return instances[instances[FINISHED]].reset_index(drop=True)


def robot_steps(instances: pd.DataFrame) -> pd.DataFrame:
    """Each robot's consecutive activity instances within a case and the time it was idle
    between them (with the two instances' message ids when the log has them)."""
    keys = [CASE, ROBOT] if ROBOT in instances.columns else [CASE]
    ordered = instances.sort_values(keys, kind="stable")  # instances come in start order
    by_robot = ordered.groupby(keys, sort=False, dropna=False)
    following = by_robot.shift(-1)
    busy_until = by_robot[TIMESTAMP].cummax()  # the latest completion so far
    steps = pd.DataFrame(
        {
            CASE: ordered[CASE],
            ROBOT: ordered[ROBOT] if ROBOT in ordered.columns else None,
            "source": ordered[ACTIVITY],
            "target": following[ACTIVITY],
            "source_end": busy_until,
            "target_start": following[START_TIMESTAMP],
        }
    )
    if MSG_ID in ordered.columns:
        steps["source_msg_id"] = ordered[MSG_ID]
        steps["target_msg_id"] = following[MSG_ID]
    steps = steps.dropna(subset=["target"])
    gap = (steps["target_start"] - steps["source_end"]).dt.total_seconds()
    steps[WAIT] = gap.clip(lower=0)
    return steps.reset_index(drop=True)


def activity_durations(instances: pd.DataFrame) -> pd.DataFrame:
    """Per activity and robot: how many instances and their mean, median, max, total duration."""
    keys = [ACTIVITY] + ([ROBOT] if ROBOT in instances.columns else [])
    table = instances.groupby(keys, sort=True, dropna=False)[DURATION].agg(
        ["count", "mean", "median", "max", "sum"]
    )
    table = table.rename(columns={"sum": "total"}).reset_index()
    return table.rename(columns={ACTIVITY: "activity"})


def transition_waits(steps: pd.DataFrame) -> pd.DataFrame:
    """Per transition and robot: the waits between the two activities, slowest (mean) first."""
    table = steps.groupby(["source", "target", ROBOT], sort=False, dropna=False)[WAIT].agg(
        ["count", "mean", "median", "max", "sum"]
    )
    table = table.rename(columns={"sum": "total"}).reset_index()
    return table.sort_values(["mean", "count"], ascending=[False, False]).reset_index(drop=True)


def case_durations(instances: pd.DataFrame) -> pd.DataFrame:
    """Per case: first start, last completion, duration in seconds, instances and robots."""
    grouped = instances.groupby(CASE, sort=True)
    table = grouped.agg(
        start=(START_TIMESTAMP, "min"), end=(TIMESTAMP, "max"), activities=(ACTIVITY, "size")
    )
    table["duration"] = (table["end"] - table["start"]).dt.total_seconds()
    if ROBOT in instances.columns:
        table["robots"] = grouped[ROBOT].nunique()
    return table.reset_index()


def _focus(instances: pd.DataFrame, activity: str | None, robot: str | None) -> pd.DataFrame:
    keep = pd.Series(True, index=instances.index)
    if activity is not None:
        keep &= instances[ACTIVITY] == activity
    if robot is not None and ROBOT in instances.columns:
        keep &= instances[ROBOT] == robot
    return instances[keep]


def _touches(steps: pd.DataFrame, activity: str | None, robot: str | None) -> pd.Series:
    keep = pd.Series(True, index=steps.index)
    if activity is not None:
        keep &= (steps["source"] == activity) | (steps["target"] == activity)
    if robot is not None:
        keep &= steps[ROBOT] == robot
    return keep


def _transition_name(row: pd.Series) -> str:
    robot = f" ({row[ROBOT]})" if isinstance(row[ROBOT], str) else ""
    return f"{row['source']} -> {row['target']}{robot}"


def _durations_figure(instances: pd.DataFrame):
    import plotly.express as px

    return px.box(
        instances.rename(columns={ACTIVITY: "activity"}),
        x="activity",
        y=DURATION,
        color=ROBOT if ROBOT in instances.columns else None,
        title="Activity durations (s)",
    )


def _waiting_figure(waiting: pd.DataFrame):
    import plotly.express as px

    top = waiting.head(15).assign(transition=lambda t: t.apply(_transition_name, axis=1))
    return px.bar(top, x="transition", y="mean", title="Slowest transitions: mean wait (s)")


def _cases_figure(cases: pd.DataFrame):
    import plotly.express as px

    return px.bar(cases.astype({CASE: str}), x=CASE, y="duration", title="Case durations (s)")
