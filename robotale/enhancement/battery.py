"""Battery: level over time per robot, what each activity drains, low-battery events and what
they caused, energy per case.

``battery`` is a percentage (0-100). An activity's use is its working time only: the level at
its start minus the level at its completion (the events' own levels, else the robot's last
sample before). What a robot uses while it waits between activities is its ``waiting`` row, so
idle drain never lands on the activity that follows. A low-battery event is the moment a
robot's level falls below the threshold (once per fall, per case), or an event of the activity
that tags it, such as the thesis' ``low_battery``; for each the perspective lists what the
robot did next. Energy per case: per robot, the percentage points it used (every fall of its
level added up) and charged (every rise) from its first level in the log to its last: a log
has levels only at a robot's events, so a robot charging on its base before its first event,
or driving on after its last, used what the log cannot show, and a robot without events has
no figures. A log without battery levels says so; its figures are missing, never 0.

A battery belongs to one robot: every figure is per robot (and run), never a sum over robots,
whose batteries differ. Use is never negative: where a level rose (a robot charging during an
activity or while it waits) that is ``charged``, apart from ``used``. The levels chart breaks
each robot's line between runs, so the time between two runs draws no ramp.
"""

from __future__ import annotations

import numpy as np
import pandas as pd
import plotly.graph_objects as go

from robotale.discovery.instances import DURATION, FINISHED, START_TIMESTAMP
from robotale.enhancement.context import LogAnalysis, analysis_of
from robotale.enhancement.followed import what_followed
from robotale.enhancement.performance import WAIT, finished_instances, shared_steps
from robotale.enhancement.result import (
    Figures,
    Perspective,
    focus_events,
    focus_label,
    no_data,
)
from robotale.eventlog.schema import ACTIVITY, BATTERY, CASE, ROBOT, TIMESTAMP
from robotale.thresholds import LOW_BATTERY_PERCENT

LOW_ACTIVITY = "low_battery"
NO_LEVELS = "no battery levels"
#: the row of the consumption table for what a robot uses between its activities
IDLE = "(waiting)"


def battery_perspective(
    log: pd.DataFrame | LogAnalysis,
    *,
    activity: str | None = None,
    robot: str | None = None,
    threshold: float = LOW_BATTERY_PERCENT,
    low_activity: str | None = LOW_ACTIVITY,
    following: int = 3,
) -> Perspective:
    """Battery levels per robot, what each activity consumed, and low-battery events with the
    ``following`` activities the robot performed next."""
    analysis = analysis_of(log)
    log = analysis.log
    levels = shared_levels(analysis)
    lows = _low_battery_events(analysis, levels, threshold, low_activity)
    if levels.empty and lows.empty:
        return no_data("battery", f"the log has {NO_LEVELS} and no low-battery events.")
    lows = _with_what_followed(lows, analysis, following)
    focused = focus_events(levels, activity, robot) if not levels.empty else levels
    if activity is not None or robot is not None:
        lows = lows[_low_focus(lows, activity, robot)]
        if focused.empty and lows.empty:
            return no_data("battery", f"no battery data for {focus_label(activity, robot)}.")
    consumption = activity_consumption(analysis, activity=activity, robot=robot)
    energy = case_energy(focused)
    return Perspective(
        name="battery",
        tables={
            "consumption": consumption,
            "low_battery": lows,
            "energy": energy,
            "levels": _level_table(focused),
        },
        figures=Figures({"levels": lambda: _levels_figure(focused, lows)}),
        summary={
            "robots": sorted(focused[ROBOT].dropna().unique()) if ROBOT in focused else [],
            "low_battery_events": len(lows),
            "threshold": threshold,
            **_energy_summary(consumption, energy),
        },
    )


def low_battery_events(
    log: pd.DataFrame,
    *,
    threshold: float = LOW_BATTERY_PERCENT,
    low_activity: str | None = LOW_ACTIVITY,
) -> pd.DataFrame:
    """When each robot's battery fell below ``threshold``, and the events of ``low_activity``."""
    return _low_battery_events(analysis_of(log), _levels(log), threshold, low_activity)


def _low_battery_events(
    analysis: LogAnalysis, levels: pd.DataFrame, threshold: float, low_activity: str | None
) -> pd.DataFrame:
    found = [_threshold_crossings(levels, threshold)]
    if low_activity is not None:
        moments = _tagged_moments(analysis, low_activity)
        found.append(_low_rows(moments, f"activity {low_activity}"))
    found = [f for f in found if not f.empty]
    if not found:
        return pd.DataFrame(columns=[CASE, ROBOT, TIMESTAMP, BATTERY, "source"])
    return pd.concat(found).sort_values([CASE, TIMESTAMP], kind="stable").reset_index(drop=True)


def activity_consumption(
    log: pd.DataFrame | LogAnalysis, *, activity: str | None = None, robot: str | None = None
) -> pd.DataFrame:
    """Per activity and robot: the battery percentage points its instances used over their
    working time, in total, per instance and per minute, and the level at their starts; a
    ``(waiting)`` row per robot for what it used while idle between activities."""
    analysis = analysis_of(log)
    levels = shared_levels(analysis)
    if levels.empty:
        return pd.DataFrame()
    instances = analysis.instances(carry=[BATTERY])
    instances = instances[instances[FINISHED]]
    instances = _fill_levels(instances, levels)
    idle = _idle_use(analysis, levels)
    chosen = focus_events(instances, activity, robot).dropna(subset=[BATTERY, f"start_{BATTERY}"])
    if chosen.empty:
        return pd.DataFrame()
    change = chosen[f"start_{BATTERY}"] - chosen[BATTERY]
    chosen = chosen.assign(used=change.clip(lower=0), charged=(-change).clip(lower=0))
    keys = [ACTIVITY] + ([ROBOT] if ROBOT in chosen.columns else [])
    table = chosen.groupby(keys, sort=True).agg(
        instances=("used", "size"),
        used=("used", "sum"),
        charged=("charged", "sum"),
        seconds=(DURATION, "sum"),
        start_level_mean=(f"start_{BATTERY}", "mean"),
        start_level_min=(f"start_{BATTERY}", "min"),
    )
    table = table.reset_index()
    if activity is None and not idle.empty:
        mine = idle if robot is None or ROBOT not in idle.columns else idle[idle[ROBOT] == robot]
        table = pd.concat([table, mine], ignore_index=True)
    table["used_per_instance"] = table["used"] / table["instances"]
    table["used_per_minute"] = table["used"] / (table["seconds"] / 60).where(table["seconds"] > 0)
    return table.rename(columns={ACTIVITY: "activity"})


def case_energy(levels: pd.DataFrame) -> pd.DataFrame:
    """Per case and robot: levels at its first and last sample, lowest level, percentage
    points used (falls added up) and charged (rises added up), and the time they cover
    (``observed_from`` and ``observed_to``: a log has levels only at a robot's events, so
    what it used before its first event or after its last is not in it)."""
    keys = [k for k in (CASE, ROBOT) if k in levels.columns]
    if levels.empty or not keys:
        return pd.DataFrame()
    change = levels.groupby(keys, sort=False)[BATTERY].diff()
    grouped = levels.assign(_fall=(-change).clip(lower=0), _rise=change.clip(lower=0)).groupby(
        keys, sort=True
    )
    return grouped.agg(
        first_level=(BATTERY, "first"),
        last_level=(BATTERY, "last"),
        lowest_level=(BATTERY, "min"),
        used=("_fall", "sum"),
        charged=("_rise", "sum"),
        observed_from=(TIMESTAMP, "first"),
        observed_to=(TIMESTAMP, "last"),
    ).reset_index()


def _fill_levels(instances: pd.DataFrame, levels: pd.DataFrame) -> pd.DataFrame:
    """Levels at an instance's start and completion where its events carry none: the robot's
    last sample at or before that time; for a start before the robot's first sample, its
    first sample up to the completion (samples often begin once the first activity runs, and
    that activity's use would otherwise go uncounted)."""
    keys = [k for k in (CASE, ROBOT) if k in instances.columns and k in levels.columns]
    samples = levels[[*keys, TIMESTAMP, BATTERY]].dropna().sort_values(TIMESTAMP, kind="stable")
    filled = instances.copy()
    for when, column in ((START_TIMESTAMP, f"start_{BATTERY}"), (TIMESTAMP, BATTERY)):
        missing = filled[column].isna() & filled[when].notna()
        if missing.any():
            filled.loc[missing, column] = _sample_at(filled[missing], when, samples, keys)
    start = f"start_{BATTERY}"
    missing = filled[start].isna() & filled[START_TIMESTAMP].notna()
    if missing.any():
        first = _sample_at(filled[missing], START_TIMESTAMP, samples, keys, "forward")
        filled.loc[missing, start] = first
    return filled


def _sample_at(
    rows: pd.DataFrame,
    when: str,
    samples: pd.DataFrame,
    keys: list[str],
    direction: str = "backward",
) -> np.ndarray:
    """Per row, the robot's level at ``when``: its last sample at or before (``backward``), or
    its first sample at or after that is no later than the row's completion (``forward``)."""
    wanted = rows[[*keys, when]].rename(columns={when: TIMESTAMP})
    wanted = wanted.assign(_row=np.arange(len(rows)), _end=rows[TIMESTAMP].to_numpy())
    wanted = wanted.sort_values(TIMESTAMP, kind="stable")
    found = pd.merge_asof(
        wanted,
        samples.assign(_at=samples[TIMESTAMP]),
        on=TIMESTAMP,
        by=keys or None,
        direction=direction,
    )
    if direction == "forward":
        found.loc[~(found["_at"] <= found["_end"]), BATTERY] = np.nan
    values = np.full(len(rows), np.nan)
    values[found["_row"].to_numpy()] = found[BATTERY].to_numpy(float)
    return values


def _idle_use(analysis: LogAnalysis, levels: pd.DataFrame) -> pd.DataFrame:
    """Per robot, what it used between its activities: the level at one activity's completion
    minus the level at the next one's start, over the waits between them."""
    if ROBOT not in finished_instances(analysis).columns:
        return pd.DataFrame()
    steps = shared_steps(analysis).dropna(subset=[WAIT])
    steps = steps[steps[WAIT] > 0]
    if steps.empty:
        return pd.DataFrame()
    probe = pd.DataFrame(
        {
            CASE: steps[CASE],
            ROBOT: steps[ROBOT],
            START_TIMESTAMP: steps["source_end"],
            TIMESTAMP: steps["target_start"],
            f"start_{BATTERY}": np.nan,
            BATTERY: np.nan,
        }
    )
    probe = _fill_levels(probe, levels).dropna(subset=[BATTERY, f"start_{BATTERY}"])
    change = probe[f"start_{BATTERY}"] - probe[BATTERY]
    probe = probe.assign(
        used=change.clip(lower=0), charged=(-change).clip(lower=0), seconds=steps[WAIT]
    )
    table = probe.groupby(ROBOT, sort=True).agg(
        instances=("used", "size"),
        used=("used", "sum"),
        charged=("charged", "sum"),
        seconds=("seconds", "sum"),
    )
    return table.reset_index().assign(**{ACTIVITY: IDLE})


def _energy_summary(consumption: pd.DataFrame, energy: pd.DataFrame) -> dict:
    """Per robot: the mean percentage points it used per run, and what it used while waiting;
    never a sum over robots."""
    if energy.empty:
        return {"battery_levels": f"the log has {NO_LEVELS}"}
    robots = energy[ROBOT] if ROBOT in energy.columns else pd.Series("all", index=energy.index)
    per_run = energy.groupby(robots.astype(str), sort=True)["used"].mean()
    summary = {
        "used_per_run": {robot: float(used) for robot, used in per_run.items()},
        "most_used_robot": str(per_run.idxmax()),
    }
    if not consumption.empty:
        idle = consumption["activity"] == IDLE
        work = consumption[~idle].sort_values("used", ascending=False)
        summary["most_used_by"] = None if work.empty else str(work["activity"].iloc[0])
        waiting = consumption[idle]
        if ROBOT in waiting.columns and not waiting.empty:
            used = waiting.set_index(waiting[ROBOT].astype(str))["used"]
            summary["used_while_waiting"] = {robot: float(u) for robot, u in used.items()}
    return summary


def shared_levels(analysis: LogAnalysis) -> pd.DataFrame:
    """:func:`_levels` of the analysed log, sorted once per analysis (a copy of the log's rows
    with a level)."""
    return analysis.shared("levels", lambda: _levels(analysis.log))


def _levels(log: pd.DataFrame) -> pd.DataFrame:
    """The rows with a battery level (samples included), in time order; none when the column
    is missing, empty or 0 throughout (a reader's filler, not a robot running on empty)."""
    if BATTERY not in log.columns:
        return log.iloc[0:0]
    levels = log.dropna(subset=[BATTERY])
    if levels.empty or levels[BATTERY].eq(0).all():
        return log.iloc[0:0]
    return levels.sort_values(TIMESTAMP, kind="stable")


def _threshold_crossings(levels: pd.DataFrame, threshold: float) -> pd.DataFrame:
    if levels.empty:
        return levels
    keys = [k for k in (CASE, ROBOT) if k in levels.columns]
    below = levels[BATTERY] < threshold
    before = below.groupby([levels[k] for k in keys], sort=False).shift(1, fill_value=False)
    return _low_rows(levels[below & ~before.astype(bool)], f"below {threshold:g}%")


def _low_rows(events: pd.DataFrame, source: str) -> pd.DataFrame:
    columns = [c for c in (CASE, ROBOT, TIMESTAMP, ACTIVITY, BATTERY) if c in events.columns]
    return events[columns].assign(source=source)


def _tagged_moments(analysis: LogAnalysis, activity: str) -> pd.DataFrame:
    """One row per instance of the tagged ``activity``, at its start with the level then: a
    tool may write such a moment as a start/complete pair, an instant event or a lone
    completion."""
    # the log's instances, shared with the consumption table, rather than the tagged rows'
    # own: instances pair within one activity and keep the log's order, so they are the same
    carry = [BATTERY] if BATTERY in analysis.log.columns else []
    instances = analysis.instances(carry=carry)
    if ACTIVITY in instances.columns:
        instances = instances[instances[ACTIVITY].astype("string").eq(activity).fillna(False)]
    else:
        instances = instances.iloc[0:0]
    moments = instances.assign(**{TIMESTAMP: instances[START_TIMESTAMP]})
    if f"start_{BATTERY}" in moments.columns:  # absent when no instance was found
        moments[BATTERY] = moments[f"start_{BATTERY}"].fillna(moments[BATTERY])
    return moments


def _with_what_followed(lows: pd.DataFrame, analysis: LogAnalysis, following: int) -> pd.DataFrame:
    """Adds ``then``: the next activities the robot started, and ``until_end``: seconds to its
    last completion in the case."""
    if lows.empty:
        return lows.assign(then=pd.Series(dtype=object), until_end=pd.Series(dtype=float))
    instances = analysis.instances()
    keys = [CASE] + ([ROBOT] if ROBOT in instances.columns and ROBOT in lows.columns else [])
    # a moment without a case or robot is about no instance
    named = lows.dropna(subset=keys)
    found = what_followed(instances, named, keys, TIMESTAMP, following).reindex(lows.index)
    until_end = (pd.to_datetime(found["last_end"], utc=True) - lows[TIMESTAMP]).dt.total_seconds()
    known = until_end.notna().to_numpy()
    return lows.assign(
        then=found["then"].fillna("").tolist(),
        until_end=[float(v) if k else None for v, k in zip(until_end, known, strict=True)],
    )


def _low_focus(lows: pd.DataFrame, activity: str | None, robot: str | None) -> pd.Series:
    keep = pd.Series(True, index=lows.index)
    if robot is not None and ROBOT in lows.columns:
        keep &= lows[ROBOT] == robot
    if activity is not None:
        keep &= lows["then"].str.split(" -> ").map(lambda names: activity in names) | (
            lows.get(ACTIVITY, pd.Series("", index=lows.index)) == activity
        )
    return keep


def _level_table(levels: pd.DataFrame) -> pd.DataFrame:
    columns = [c for c in (CASE, ROBOT, TIMESTAMP, ACTIVITY, BATTERY) if c in levels.columns]
    return levels[columns].reset_index(drop=True)


def _levels_figure(levels: pd.DataFrame, lows: pd.DataFrame):
    figure = go.Figure()
    robots = levels.groupby(ROBOT, sort=True) if ROBOT in levels.columns else [("all", levels)]
    for name, mine in robots if BATTERY in levels.columns else []:  # tagged lows, no levels
        times, values = broken_between_runs(mine)
        # as the text plotly writes for a time: it copies each time object it is given,
        # which takes longer than the rest of the figure
        times = np.array([t if t is None else t.isoformat() for t in times], dtype=object)
        figure.add_scatter(x=times, y=values, mode="lines", name=str(name), connectgaps=False)
    if not lows.empty:
        figure.add_scatter(
            x=lows[TIMESTAMP],
            y=lows[BATTERY] if BATTERY in lows.columns else [0] * len(lows),
            mode="markers",
            marker={"symbol": "x", "size": 10, "color": "#d62728"},
            name="low battery",
            text=lows["then"],
        )
    figure.update_layout(title="Battery level (%)", yaxis_title="%", xaxis_title="time")
    return figure


def broken_between_runs(levels: pd.DataFrame) -> tuple[np.ndarray, np.ndarray]:
    """One robot's levels in time order as x and y of a line, with a gap (``None``) where a
    run ends and the next begins: a line drawn across the time between runs would look like
    charging or draining that never happened."""
    ordered = levels.sort_values(TIMESTAMP, kind="stable")
    times = ordered[TIMESTAMP].to_numpy(object)
    values = ordered[BATTERY].to_numpy(float).astype(object)
    if CASE not in ordered.columns:
        return times, values
    cases = ordered[CASE].astype(str).to_numpy(object)
    ends = np.flatnonzero(cases[1:] != cases[:-1]) + 1
    return np.insert(times, ends, None), np.insert(values, ends, None)
