"""Performance: working and waiting time, slowest transitions, variants and case durations.

Working time is an activity instance's own duration (a start paired with its completion). An
instance that ends aborted or cancelled (interrupted, such as an exploration cut short by low
battery) is an instance all the same: its time counts, and ``interrupted`` says how many.
Waiting is measured per robot: the time before one of its activities starts during which the
robot had no activity running (its previous activities had all completed). A robot running a
long activity while others come and go, such as a drone exploring while it reports weeds, is
not waiting; and a robot waits for its own next step, not for another robot's. The two never
mix: when the log has an activity's completion but not its start, the time before it holds
its own work too, so it counts as neither (``unsplit``), never as waiting.

Per robot and case, its span (first start to last completion) = working + waiting + unsplit,
where working is the time at least one of its activities ran.
"""

from __future__ import annotations

import pandas as pd
import plotly.graph_objects as go

from robotale.discovery.instances import (
    DURATION,
    FINISHED,
    START_KNOWN,
    START_TIMESTAMP,
    interrupted,
)
from robotale.enhancement.context import LogAnalysis, analysis_of
from robotale.enhancement.result import Figures, Perspective, focus_label, no_data
from robotale.eventlog.schema import ACTIVITY, CASE, MSG_ID, ROBOT, TIMESTAMP

WAIT = "wait"
#: time before an activity whose start the log lacks: its work and any wait, not split
GAP = "gap"
VARIANT = "variant"
ARROW = " -> "


def performance_perspective(
    log: pd.DataFrame | LogAnalysis, *, activity: str | None = None, robot: str | None = None
) -> Perspective:
    """Activity durations, waiting per transition (slowest first), working and waiting time
    per robot and case, variants, and case durations.

    With ``activity`` and/or ``robot``: that activity's (class's) durations, the transitions
    into and out of it, and the cases (and their variants) it occurs in.
    """
    analysis = analysis_of(log)
    instances = finished_instances(analysis)
    if instances.empty:
        return no_data("performance", "the log has no completed activity.")
    steps = shared_steps(analysis)
    chosen = _focus(instances, activity, robot)
    if chosen.empty:
        return no_data("performance", f"no instance of {focus_label(activity, robot)}.")
    robots, cases = shared_robot_times(analysis), shared_cases(analysis)
    case_variants = shared_case_variants(analysis)
    robot_variants = robot_variant_table(robots)
    if activity is not None or robot is not None:
        steps = steps[_touches(steps, activity, robot)]
        in_focus = cases[CASE].isin(chosen[CASE])
        cases, case_variants = (
            cases[in_focus],
            case_variants[case_variants[CASE].isin(chosen[CASE])],
        )
        robot_variants = _robot_focus(robot_variants, chosen)
        robots = robots[robots[CASE].isin(chosen[CASE])]
    waiting = transition_waits(steps)
    tables = {
        "activities": activity_durations(chosen),
        "waiting": waiting,
        "cases": cases,
        "robots": robots.drop(columns=VARIANT),
        "variants": variant_summary(case_variants, "duration"),
        "robot_variants": variant_summary(robot_variants, "span", by_robot=True),
    }
    return Perspective(
        name="performance",
        tables=tables,
        figures=Figures(
            {
                "durations": lambda: _durations_figure(chosen),
                "waiting": lambda: _waiting_figure(waiting),
                "cases": lambda: _cases_figure(cases),
            }
        ),
        summary=_summary(cases, waiting, tables),
    )


def finished_instances(log: pd.DataFrame | LogAnalysis) -> pd.DataFrame:
    """The activity instances that completed (shared by the analysis: do not modify)."""
    analysis = analysis_of(log)

    def build() -> pd.DataFrame:
        instances = analysis.instances()
        return instances[instances[FINISHED]].reset_index(drop=True)

    return analysis.shared("finished", build)


def shared_steps(analysis: LogAnalysis) -> pd.DataFrame:
    """:func:`robot_steps` of the finished instances, built once per analysis."""
    return analysis.shared("steps", lambda: robot_steps(finished_instances(analysis)))


def shared_robot_times(analysis: LogAnalysis) -> pd.DataFrame:
    """:func:`robot_times` of the finished instances, built once per analysis."""
    return analysis.shared(
        "robot_times",
        lambda: robot_times(finished_instances(analysis), shared_steps(analysis)),
    )


def shared_cases(analysis: LogAnalysis) -> pd.DataFrame:
    """:func:`case_durations` with the robots' times, built once per analysis."""
    return analysis.shared(
        "cases",
        lambda: case_durations(finished_instances(analysis), shared_robot_times(analysis)),
    )


def shared_case_variants(analysis: LogAnalysis) -> pd.DataFrame:
    """:func:`case_variant_table` of the finished instances, built once per analysis."""

    def build() -> pd.DataFrame:
        # the case table has each case's start, end and duration: only the paths are new
        instances, cases = finished_instances(analysis), shared_cases(analysis)
        paths = _paths(instances, [CASE]).reindex(cases[CASE]).to_numpy()
        table = cases[[CASE, "start", "end"]].assign(**{VARIANT: paths})
        return table.assign(duration=cases["duration"])

    return analysis.shared("case_variants", build)


def robot_steps(instances: pd.DataFrame) -> pd.DataFrame:
    """Each robot's consecutive activity instances within a case and the time it was idle
    between them (``wait``; missing when the next activity's start is unknown, the time then
    being in ``gap``), with the two instances' message ids when the log has them."""
    keys = [CASE, ROBOT] if ROBOT in instances.columns else [CASE]
    ordered = instances.sort_values(keys, kind="stable")  # instances come in start order
    by_robot = ordered.groupby(keys, sort=False, dropna=False)
    # only the columns a step reads from the next instance: shifting them all costs more
    wanted = [c for c in (ACTIVITY, START_TIMESTAMP, MSG_ID, START_KNOWN) if c in ordered]
    following = by_robot[wanted].shift(-1)
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
    known = following[START_KNOWN] if START_KNOWN in following.columns else True
    steps["_known"] = pd.Series(known, index=steps.index).fillna(True).astype(bool)
    steps = steps.dropna(subset=["target"])
    gap = (steps["target_start"] - steps["source_end"]).dt.total_seconds().clip(lower=0)
    steps[WAIT] = gap.where(steps["_known"])
    steps[GAP] = gap.where(~steps["_known"], 0.0)
    return steps.drop(columns="_known").reset_index(drop=True)


def robot_times(instances: pd.DataFrame, steps: pd.DataFrame) -> pd.DataFrame:
    """Per case and robot: span, working, waiting and unsplit seconds, activities, variant."""
    keys = [CASE, ROBOT] if ROBOT in instances.columns else [CASE]
    grouped = instances.groupby(keys, sort=True, dropna=False)
    table = grouped.agg(
        start=(START_TIMESTAMP, "min"), end=(TIMESTAMP, "max"), activities=(ACTIVITY, "size")
    )
    table[VARIANT] = _paths(instances, keys)
    table["span"] = (table["end"] - table["start"]).dt.total_seconds()
    idle = steps.groupby(keys, sort=False, dropna=False)[[WAIT, GAP]].sum()
    table = table.join(idle)
    table[[WAIT, GAP]] = table[[WAIT, GAP]].fillna(0.0)
    table["working"] = (table["span"] - table[WAIT] - table[GAP]).clip(lower=0)
    table = table.rename(columns={WAIT: "waiting", GAP: "unsplit"}).reset_index()
    if ROBOT not in table.columns:
        table[ROBOT] = None
    return table


def case_durations(instances: pd.DataFrame, robots: pd.DataFrame | None = None) -> pd.DataFrame:
    """Per case: first start, last completion, duration in seconds, instances and robots, and
    (given :func:`robot_times`) the working, waiting and unsplit seconds of its robots."""
    grouped = instances.groupby(CASE, sort=True)
    table = grouped.agg(
        start=(START_TIMESTAMP, "min"), end=(TIMESTAMP, "max"), activities=(ACTIVITY, "size")
    )
    table["duration"] = (table["end"] - table["start"]).dt.total_seconds()
    if ROBOT in instances.columns:
        table["robots"] = grouped[ROBOT].nunique()
    if robots is not None:
        table = table.join(robots.groupby(CASE)[["working", "waiting", "unsplit"]].sum())
    return table.reset_index()


def case_variant_table(instances: pd.DataFrame) -> pd.DataFrame:
    """Per case: its variant (every robot's activities in start order) and duration."""
    grouped = instances.groupby(CASE, sort=True)
    table = grouped.agg(start=(START_TIMESTAMP, "min"), end=(TIMESTAMP, "max"))
    table[VARIANT] = _paths(instances, [CASE])
    table["duration"] = (table["end"] - table["start"]).dt.total_seconds()
    return table.reset_index()


def _paths(instances: pd.DataFrame, keys: list[str]) -> pd.Series:
    """Per group, its activities in start order joined by arrows (summing the strings keeps
    the join vectorised)."""
    codes, uniques = pd.factorize(instances[ACTIVITY], use_na_sentinel=False)
    labels = pd.Series(uniques).astype(str) + ARROW  # once per name, not once per instance
    names = pd.Series(labels.array.take(codes), index=instances.index)
    joined = names.groupby([instances[k] for k in keys], sort=True, dropna=False).sum()
    return joined.str.slice(stop=-len(ARROW))


def robot_variant_table(robots: pd.DataFrame) -> pd.DataFrame:
    """Per case and robot: the robot's own path (its activities in start order) and span."""
    return robots[[CASE, ROBOT, VARIANT, "span"]]


def variant_summary(variants: pd.DataFrame, seconds: str, by_robot: bool = False) -> pd.DataFrame:
    """Per variant (and robot): how many cases follow it, their share and durations, most
    frequent first."""
    keys = [ROBOT, VARIANT] if by_robot else [VARIANT]
    table = variants.groupby(keys, sort=False, dropna=False)[seconds].agg(
        ["count", "mean", "median", "max"]
    )
    table = table.rename(columns={"count": "cases"}).reset_index()
    totals = table.groupby(ROBOT, dropna=False)["cases"].transform("sum") if by_robot else None
    table["share"] = table["cases"] / (totals if by_robot else table["cases"].sum())
    table["activities"] = table[VARIANT].str.count(ARROW) + 1
    table = table.sort_values(["cases", "mean"], ascending=[False, True], kind="stable")
    return table.reset_index(drop=True)


def activity_durations(instances: pd.DataFrame) -> pd.DataFrame:
    """Per activity and robot: how many instances and their mean, median, max, total duration
    (working time only)."""
    keys = [instances[k] for k in [ACTIVITY] + ([ROBOT] if ROBOT in instances.columns else [])]
    # an instance that ended aborted or cancelled is counted, and said to be interrupted
    stopped = interrupted(instances)
    # one grouping for both columns: the keys factorised once
    both = pd.DataFrame({DURATION: instances[DURATION], "interrupted": stopped})
    grouped = both.groupby(keys, sort=True, dropna=False)
    table = grouped[DURATION].agg(["count", "mean", "median", "max", "sum"])
    if any(key.isna().any() for key in keys):  # a group with a missing key has no count
        table["interrupted"] = stopped.groupby(keys).sum()
    else:
        table["interrupted"] = grouped["interrupted"].sum()
    table = table.rename(columns={"sum": "total"}).reset_index()
    return table.rename(columns={ACTIVITY: "activity"})


def transition_waits(steps: pd.DataFrame) -> pd.DataFrame:
    """Per transition and robot: the waits between the two activities, slowest (mean) first
    (transitions into an activity whose start the log lacks have no wait and are left out)."""
    known = steps.dropna(subset=[WAIT])
    table = known.groupby(["source", "target", ROBOT], sort=False, dropna=False)[WAIT].agg(
        ["count", "mean", "median", "max", "sum"]
    )
    table = table.rename(columns={"sum": "total"}).reset_index()
    return table.sort_values(["mean", "count"], ascending=[False, False]).reset_index(drop=True)


def _summary(cases: pd.DataFrame, waiting: pd.DataFrame, tables: dict) -> dict:
    working, waited = float(cases["working"].sum()), float(cases["waiting"].sum())
    variants = tables["variants"]
    return {
        "cases": len(cases),
        "case_duration_mean": float(cases["duration"].mean()),
        "case_duration_median": float(cases["duration"].median()),
        "slowest_transition": None if waiting.empty else _transition_name(waiting.iloc[0]),
        "working_time": working,
        "waiting_time": waited,
        "waiting_share": waited / (working + waited) if working + waited > 0 else None,
        "variants": len(variants),
        "interrupted": int(tables["activities"]["interrupted"].sum()),
        "top_variant_cases": int(variants["cases"].iloc[0]) if len(variants) else 0,
        "robot_variants": len(tables["robot_variants"]),
    }


def _focus(instances: pd.DataFrame, activity: str | None, robot: str | None) -> pd.DataFrame:
    keep = pd.Series(True, index=instances.index)
    if activity is not None:
        keep &= instances[ACTIVITY] == activity
    if robot is not None and ROBOT in instances.columns:
        keep &= instances[ROBOT] == robot
    return instances[keep]


def _robot_focus(robot_variants: pd.DataFrame, chosen: pd.DataFrame) -> pd.DataFrame:
    """The paths of the robots and cases the focused instances belong to."""
    if ROBOT not in chosen.columns:
        return robot_variants[robot_variants[CASE].isin(chosen[CASE])]
    pairs = chosen[[CASE, ROBOT]].drop_duplicates()
    return robot_variants.merge(pairs, on=[CASE, ROBOT])


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
    """Box plots of working time per activity, one colour per robot (plain traces: plotly
    express spends seconds preparing a large frame; fixed-width text arrays, which plotly
    copies whole rather than string by string)."""
    figure = go.Figure()
    robots = (
        instances.groupby(ROBOT, sort=True) if ROBOT in instances.columns else [("", instances)]
    )
    for robot, mine in robots:
        codes, names = pd.factorize(mine[ACTIVITY], use_na_sentinel=False)
        names = pd.Series(names, dtype=object).astype(str).to_numpy(str)[codes]  # once a name
        figure.add_box(x=names, y=mine[DURATION].to_numpy(), name=str(robot))
    return figure.update_layout(
        boxmode="group", title="Activity durations: working time (s)", yaxis_title=DURATION
    )


def _waiting_figure(waiting: pd.DataFrame):
    import plotly.express as px  # 0.6 s to import: only a figure needs it

    top = waiting.head(15).assign(transition=lambda t: t.apply(_transition_name, axis=1))
    return px.bar(top, x="transition", y="mean", title="Slowest transitions: mean wait (s)")


def _cases_figure(cases: pd.DataFrame):
    import plotly.express as px  # 0.6 s to import: only a figure needs it

    parts = cases.astype({CASE: str}).melt(
        id_vars=[CASE], value_vars=["working", "waiting", "unsplit"], var_name="time"
    )
    return px.bar(
        parts, x=CASE, y="value", color="time", title="Case time per robot: working and waiting (s)"
    )
