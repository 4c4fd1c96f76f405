"""Battery: level over time per robot, consumption per activity, low-battery events.

``battery`` is a percentage (0-100). A low-battery event is the moment a robot's level falls
below the threshold (once per fall, per case), or an event of the activity that tags it, such
as the thesis' ``low_battery``. For each the perspective lists what the robot did next.
"""

from __future__ import annotations

import pandas as pd

from robotale.discovery.instances import DURATION, FINISHED, START_TIMESTAMP, activity_instances
from robotale.enhancement.result import Perspective, focus_events, focus_label, no_data
from robotale.eventlog.schema import ACTIVITY, BATTERY, CASE, LIFECYCLE, ROBOT, START, TIMESTAMP

LOW_ACTIVITY = "low_battery"


def battery_perspective(
    log: pd.DataFrame,
    *,
    activity: str | None = None,
    robot: str | None = None,
    threshold: float = 20.0,
    low_activity: str | None = LOW_ACTIVITY,
    following: int = 3,
) -> Perspective:
    """Battery levels per robot, what each activity consumed, and low-battery events with the
    ``following`` activities the robot performed next."""
    levels = _levels(log)
    lows = low_battery_events(log, threshold=threshold, low_activity=low_activity)
    if levels.empty and lows.empty:
        return no_data("battery", "the log has no battery levels and no low-battery events.")
    lows = _with_what_followed(lows, log, following)
    focused = focus_events(levels, activity, robot) if not levels.empty else levels
    if activity is not None or robot is not None:
        lows = lows[_low_focus(lows, activity, robot)]
        if focused.empty and lows.empty:
            return no_data("battery", f"no battery data for {focus_label(activity, robot)}.")
    consumption = activity_consumption(log, activity=activity, robot=robot)
    return Perspective(
        name="battery",
        tables={"consumption": consumption, "low_battery": lows, "levels": _level_table(focused)},
        figures={"levels": _levels_figure(focused, lows)},
        summary={
            "robots": sorted(focused[ROBOT].dropna().unique()) if ROBOT in focused else [],
            "low_battery_events": len(lows),
            "threshold": threshold,
        },
    )


def low_battery_events(
    log: pd.DataFrame, *, threshold: float = 20.0, low_activity: str | None = LOW_ACTIVITY
) -> pd.DataFrame:
    """When each robot's battery fell below ``threshold``, and the events of ``low_activity``."""
    found = [_threshold_crossings(_levels(log), threshold)]
    if low_activity is not None:
        tagged = log[log[ACTIVITY].astype("string").eq(low_activity).fillna(False)]
        tagged = tagged[_is_start_or_instant(tagged)]
        found.append(_low_rows(tagged, f"activity {low_activity}"))
    found = [f for f in found if not f.empty]
    if not found:
        return pd.DataFrame(columns=[CASE, ROBOT, TIMESTAMP, BATTERY, "source"])
    return pd.concat(found).sort_values([CASE, TIMESTAMP], kind="stable").reset_index(drop=True)


def activity_consumption(
    log: pd.DataFrame, *, activity: str | None = None, robot: str | None = None
) -> pd.DataFrame:
    """Per activity and robot: the battery percentage points its instances used, in total,
    per instance and per minute (from the level at its start to the level at its end)."""
    if BATTERY not in log.columns or log[BATTERY].isna().all():
        return pd.DataFrame()
    instances = activity_instances(focus_events(log, activity, robot), carry=[BATTERY])
    instances = instances[instances[FINISHED]].dropna(subset=[BATTERY, f"start_{BATTERY}"])
    if instances.empty:
        return pd.DataFrame()
    instances = instances.assign(used=instances[f"start_{BATTERY}"] - instances[BATTERY])
    keys = [ACTIVITY] + ([ROBOT] if ROBOT in instances.columns else [])
    table = instances.groupby(keys, sort=True).agg(
        instances=("used", "size"), used=("used", "sum"), seconds=(DURATION, "sum")
    )
    table["used_per_instance"] = table["used"] / table["instances"]
    table["used_per_minute"] = table["used"] / (table["seconds"] / 60).where(table["seconds"] > 0)
    return table.reset_index().rename(columns={ACTIVITY: "activity"})


def _levels(log: pd.DataFrame) -> pd.DataFrame:
    if BATTERY not in log.columns:
        return log.iloc[0:0]
    return log.dropna(subset=[BATTERY]).sort_values(TIMESTAMP, kind="stable")


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


def _is_start_or_instant(events: pd.DataFrame) -> pd.Series:
    if LIFECYCLE not in events.columns:
        return pd.Series(True, index=events.index)
    lifecycle = events[LIFECYCLE].astype("string").fillna("none").str.lower()
    return lifecycle.isin([START, "none"])


def _with_what_followed(lows: pd.DataFrame, log: pd.DataFrame, following: int) -> pd.DataFrame:
    """Adds ``then``: the next activities the robot started, and ``until_end``: seconds to its
    last completion in the case."""
    if lows.empty:
        return lows.assign(then=pd.Series(dtype=object), until_end=pd.Series(dtype=float))
    instances = activity_instances(log)
    then, until_end = [], []
    for _, low in lows.iterrows():
        mine = instances[(instances[CASE] == low[CASE]) & _same_robot(instances, low)]
        after = mine[mine[START_TIMESTAMP] > low[TIMESTAMP]]
        then.append(" -> ".join(after[ACTIVITY].astype(str).head(following)))
        end = mine[TIMESTAMP].max()
        until_end.append((end - low[TIMESTAMP]).total_seconds() if pd.notna(end) else None)
    return lows.assign(then=then, until_end=until_end)


def _same_robot(instances: pd.DataFrame, low: pd.Series) -> pd.Series:
    if ROBOT not in instances.columns or ROBOT not in low.index:
        return pd.Series(True, index=instances.index)
    return instances[ROBOT] == low[ROBOT]


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
    import plotly.graph_objects as go

    figure = go.Figure()
    robots = levels.groupby(ROBOT, sort=True) if ROBOT in levels.columns else [("all", levels)]
    for name, mine in robots:
        figure.add_scatter(x=mine[TIMESTAMP], y=mine[BATTERY], mode="lines", name=str(name))
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
