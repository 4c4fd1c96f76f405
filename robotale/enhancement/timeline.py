"""One run at a glance: a lane per robot with its activity instances as bars, the messages
between robots as arrows from sender to receiver (a lost message marked where it was sent, a
message whose type the log tags no receive of marked apart: it may have arrived) and, on its
own axis below the lanes, each robot's battery as a line. Each activity has one colour, the
same on every page (:mod:`robotale.enhancement.colours`).

The figure is plain plotly JSON, so the HTML report embeds it and the dashboard draws the same
thing from a JSON endpoint.
"""

from __future__ import annotations

import json
from dataclasses import dataclass, field
from typing import Any

import pandas as pd
import plotly.graph_objects as go

from robotale.discovery.instances import FINISHED, START_TIMESTAMP
from robotale.enhancement.colours import activity_colours, log_colours
from robotale.enhancement.communication import message_table
from robotale.enhancement.context import LogAnalysis
from robotale.enhancement.performance import case_durations, finished_instances
from robotale.errors import InputError
from robotale.eventlog.schema import (
    ACTIVITY,
    BATTERY,
    CASE,
    MSG_ID,
    ROBOT,
    SOURCE_INDEX,
    SOURCE_TOPIC,
    TIMESTAMP,
)

#: the battery axis' share of the figure's height, below the lanes, and the gap between them
BATTERY_SHARE, GAP = 0.22, 0.06
#: pixels the battery axis adds to the figure's height
BATTERY_HEIGHT = 160
#: the lane of events whose robot the log does not name
NO_ROBOT = "(no robot)"
LOST_COLOUR = "#d62728"
MESSAGE_COLOUR = "#555555"


@dataclass(slots=True)
class Timeline:
    """The data of one run's timeline: ``bars`` (robot, activity, start, end, source: where
    its events were recorded, seconds), ``messages`` (msg_id, sender, receiver, sent,
    received, lost, unobserved, delayed) and ``battery`` (robot, time, level)."""

    case: str
    robots: list[str]
    bars: pd.DataFrame
    messages: pd.DataFrame
    battery: pd.DataFrame
    #: activity -> colour, of the whole log (:mod:`robotale.enhancement.colours`)
    colours: dict[str, str] = field(default_factory=dict)

    @property
    def lost(self) -> int:
        return int(self.messages["lost"].sum()) if not self.messages.empty else 0

    def counts(self) -> dict[str, Any]:
        """The run, its robots and how many bars, messages, lost ones and battery readings."""
        return {
            "case": self.case,
            "robots": self.robots,
            "bars": len(self.bars),
            "messages": len(self.messages),
            "lost": self.lost,
            "battery_samples": len(self.battery),
        }

    def to_dict(self) -> dict[str, Any]:
        return {**self.counts(), "figure": json.loads(timeline_figure(self).to_json())}


def run_list(log: pd.DataFrame) -> pd.DataFrame:
    """The runs of ``log`` with their start, end and duration, in start order."""
    instances = finished_instances(log)
    if instances.empty:
        return pd.DataFrame(columns=["case", "start", "end", "duration"])
    runs = case_durations(instances)[[CASE, "start", "end", "duration"]]
    return runs.sort_values("start", kind="stable").rename(columns={CASE: "case"})


def case_timeline(log: pd.DataFrame, case: str) -> Timeline:
    """The timeline of run ``case`` of ``log`` (an :class:`InputError` naming the runs there
    are when it has no such run)."""
    events = _case_events(log, case)
    bars = _bars(events)
    messages = _messages(events)
    battery = _battery(events)
    robots = sorted(set(bars["robot"]) | set(battery["robot"]) | _message_robots(messages))
    return Timeline(str(case), robots, bars, messages, battery, log_colours(log))


def case_messages(log: pd.DataFrame, case: str) -> tuple[pd.DataFrame, set[str]]:
    """The messages of :func:`case_timeline` and the robots they and the battery readings
    give a lane, without its bars (a run replayed needs its messages, not their drawing)."""
    events = _case_events(log, case)
    messages = _messages(events)
    return messages, set(_battery(events)["robot"]) | _message_robots(messages)


def _case_events(log: pd.DataFrame, case: str) -> pd.DataFrame:
    """The events of run ``case``, each with its robot (an :class:`InputError` naming the
    runs there are when it has no such run)."""
    cases = log[CASE].astype("string")
    events = log[cases.eq(str(case)).fillna(False).to_numpy(bool)]
    if events.empty:
        known = ", ".join(sorted(cases.dropna().unique())[:5])
        raise InputError(f"the log has no run {case!r}; its runs include {known}.")
    return events.assign(**{ROBOT: _robots(events)})


def _robots(events: pd.DataFrame) -> pd.Series:
    if ROBOT not in events.columns:
        return pd.Series(NO_ROBOT, index=events.index)
    return events[ROBOT].astype("string").fillna(NO_ROBOT)


def _bars(events: pd.DataFrame) -> pd.DataFrame:
    sourced = [c for c in (SOURCE_TOPIC, SOURCE_INDEX) if c in events.columns]
    if len(sourced) == 2:  # a log prepared from bags says which message each event came from
        instances = LogAnalysis(events).instances(sourced)
        instances = instances[instances[FINISHED]]
    else:
        instances = finished_instances(events)
    bars = pd.DataFrame(
        {
            "robot": instances[ROBOT].astype(str),
            "activity": instances[ACTIVITY].astype(str),
            "start": instances[START_TIMESTAMP],
            "end": instances[TIMESTAMP],
            "source": _sources(instances) if len(sourced) == 2 else "",
        }
    )
    bars["seconds"] = (bars["end"] - bars["start"]).dt.total_seconds()
    return bars.sort_values(["start", "robot"], kind="stable").reset_index(drop=True)


def _sources(instances: pd.DataFrame) -> list[str]:
    """Where each instance's start and end were recorded: ``/r1/mode #3 to #5`` (the topic
    and the messages' positions on it), ``""`` where the log does not say."""
    ends = zip(
        instances[f"start_{SOURCE_TOPIC}"],
        instances[f"start_{SOURCE_INDEX}"],
        instances[SOURCE_TOPIC],
        instances[SOURCE_INDEX],
        strict=True,
    )
    return [_source(*where) for where in ends]


def _source(topic: Any, index: Any, end_topic: Any, end_index: Any) -> str:
    if not _known(topic, index):
        return ""
    start = f"{topic} #{int(float(index))}"
    if not _known(end_topic, end_index):
        return start
    end = f"#{int(float(end_index))}"
    return f"{start} to {end}" if end_topic == topic else f"{start} to {end_topic} {end}"


def _known(topic: Any, index: Any) -> bool:
    return isinstance(topic, str) and bool(topic) and bool(pd.notna(index))


def _messages(events: pd.DataFrame) -> pd.DataFrame:
    columns = ["msg_id", "sender", "receiver", "sent", "received", "lost", "unobserved", "delayed"]
    table = message_table(events)
    if table.empty:
        return pd.DataFrame(columns=columns)
    named = table.drop(columns=["sent", "received"])
    named = named.rename(columns={"sent_at": "sent", "received_at": "received", MSG_ID: "msg_id"})
    return named[columns].sort_values("sent", kind="stable").reset_index(drop=True)


def _message_robots(messages: pd.DataFrame) -> set[str]:
    ends = pd.concat([messages["sender"], messages["receiver"]]).dropna().astype(str)
    # a receiver list ("a, b") or an unknown receiver is no lane of its own
    return {robot for robot in ends if robot != "unknown" and ", " not in robot}


def _battery(events: pd.DataFrame) -> pd.DataFrame:
    if BATTERY not in events.columns:
        return pd.DataFrame(columns=["robot", "time", "level"])
    levels = pd.to_numeric(events[BATTERY], errors="coerce")
    known = levels.notna().to_numpy(bool)
    table = pd.DataFrame(
        {
            "robot": events.loc[known, ROBOT].astype(str),
            "time": events.loc[known, TIMESTAMP],
            "level": levels[known],
        }
    )
    return table.sort_values(["robot", "time"], kind="stable").reset_index(drop=True)


def timeline_figure(timeline: Timeline) -> go.Figure:
    """Lanes (robots) above, battery (%) on its own axis below them, time along: a level never
    reads as a lane. Each activity has the log's colour for it."""
    figure = go.Figure()
    colours = timeline.colours or activity_colours(timeline.bars["activity"])
    for activity, bars in timeline.bars.groupby("activity", sort=True):
        figure.add_trace(_bar_trace(str(activity), bars, colours.get(str(activity))))
    if not timeline.messages.empty:
        figure.add_traces(_message_traces(timeline.messages, set(timeline.robots)))
    for robot, levels in timeline.battery.groupby("robot", sort=True):
        figure.add_trace(
            go.Scatter(
                x=levels["time"],
                y=levels["level"],
                yaxis="y2",
                mode="lines",
                name=f"battery {robot}",
                line={"width": 1.5},
            )
        )
    has_battery = not timeline.battery.empty
    lanes = 90 * len(timeline.robots) + 120
    figure.update_layout(
        title=f"run {timeline.case}",
        barmode="overlay",
        height=max(260, lanes + (BATTERY_HEIGHT if has_battery else 0)),
        yaxis={
            "categoryorder": "array",
            "categoryarray": timeline.robots,
            "title": "robot",
            "domain": [BATTERY_SHARE + GAP, 1.0] if has_battery else [0.0, 1.0],
        },
        yaxis2={
            "domain": [0.0, BATTERY_SHARE],
            "anchor": "x",
            "range": [0, 105],
            "title": "battery %",
            "visible": has_battery,
        },
        xaxis={"type": "date", "title": "time", "anchor": "y2" if has_battery else "y"},
        legend={"orientation": "h", "y": -0.2},
    )
    return figure


def _bar_trace(activity: str, bars: pd.DataFrame, colour: str | None) -> go.Bar:
    milliseconds = (bars["seconds"] * 1000).clip(lower=200)  # an instant stays visible
    return go.Bar(
        base=bars["start"],
        x=milliseconds,
        y=bars["robot"],
        orientation="h",
        name=activity,
        text=[activity] * len(bars),
        textposition="inside",
        insidetextanchor="start",
        customdata=list(zip(bars["seconds"], _from(bars), strict=True)),
        hovertemplate=(
            f"{activity}<br>%{{base}}<br>%{{customdata[0]:.1f}} s%{{customdata[1]}}<extra></extra>"
        ),
        marker={"color": colour},
        opacity=0.75,
    )


def _from(bars: pd.DataFrame) -> list[str]:
    """The hover's line saying where each bar's events were recorded, if the log says."""
    sources = bars["source"] if "source" in bars else pd.Series("", index=bars.index)
    return [f"<br>from {source}" if source else "" for source in sources]


def _message_traces(messages: pd.DataFrame, lanes: set[str]) -> list[go.Scatter]:
    """One line per delivered message (ending in an arrow head at the receiver) and a cross on
    the sender's lane for each lost one."""
    delivered = messages[messages["received"].notna() & messages["receiver"].isin(lanes)]
    xs: list = []
    ys: list = []
    for row in delivered.itertuples(index=False):
        xs += [row.sent, row.received, None]
        ys += [row.sender, row.receiver, None]
    traces = [
        go.Scatter(
            x=xs,
            y=ys,
            mode="lines+markers",
            name="message",
            line={"color": MESSAGE_COLOUR, "width": 1},
            marker={"symbol": "arrow", "angleref": "previous", "size": 10},
            hoverinfo="skip",
        )
    ]
    lost = messages[messages["lost"]]
    marker = {"symbol": "x", "size": 12, "color": LOST_COLOUR}
    traces.append(_marker_trace(lost, "lost message", marker, "lost message %{text}"))
    if "unobserved" in messages:
        # sent, but the log tags no receive of its type: it may have arrived
        unseen = messages[messages["unobserved"]]
        marker = {"symbol": "circle-open", "size": 10, "color": MESSAGE_COLOUR}
        hover = "%{text}: no receive tag of its type in the log"
        traces.append(_marker_trace(unseen, "not observed as received", marker, hover))
    return traces


def _marker_trace(messages: pd.DataFrame, name: str, marker: dict, hover: str) -> go.Scatter:
    """A marker on the sender's lane where each of ``messages`` was sent."""
    return go.Scatter(
        x=messages["sent"],
        y=messages["sender"],
        mode="markers",
        name=name,
        marker=marker,
        text=messages["msg_id"],
        hovertemplate=f"{hover}<extra></extra>",
    )
