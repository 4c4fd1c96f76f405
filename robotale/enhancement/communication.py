"""Inter-robot communication: messages sent, received, lost, latency and resends (thesis 7.2.2).

A message is one ``msg_id``. Its sends are the events whose role is send (``msg_role`` or an
activity ending in ``!``), its receives those whose role is receive (or ``?``). A message type
is named after its send activity (a message nobody was seen sending is named after its receive
activity with ``?`` turned into ``!``). Per message:

- sent: it has at least one send; received: at least one receive; lost: sent, never received;
- attempts: how many times it was sent (the send activity's starts, or its events when the log
  has no lifecycle), resends = attempts - 1;
- latency: from its first send to its first receive, resends included.
"""

from __future__ import annotations

import pandas as pd

from robotale.enhancement.result import Perspective, focus_label, no_data
from robotale.eventlog.schema import (
    ACTIVITY,
    CASE,
    COMPLETE,
    LIFECYCLE,
    MSG_ID,
    RECEIVE,
    ROBOT,
    SEND,
    START,
    TIMESTAMP,
    message_roles,
)

TYPE = "message_type"


def communication_perspective(
    log: pd.DataFrame, *, activity: str | None = None, robot: str | None = None
) -> Perspective:
    """Per message type: sent, received, lost, resends and latency; with a bar chart.

    With ``activity`` (a send ``x!`` or receive ``x?`` activity) only the messages of that
    type; with ``robot`` only the messages that robot sent or received.
    """
    messages = message_table(log)
    if messages.empty:
        return no_data("communication", "the log has no messages (no events with a msg_id).")
    if activity is not None:
        messages = messages[messages[TYPE] == _type_of(activity)]
    if robot is not None:
        messages = messages[_involving(log, messages, robot)]
    if messages.empty:
        return no_data("communication", f"no message involves {focus_label(activity, robot)}.")
    types = _by_type(messages)
    return Perspective(
        name="communication",
        tables={"message_types": types, "messages": messages},
        figures={"messages": _figure(types)},
        summary={
            "messages": len(messages),
            "sent": int(messages["sent"].sum()),
            "received": int(messages["received"].sum()),
            "lost": int(messages["lost"].sum()),
            "resends": int(messages["resends"].sum()),
        },
    )


def message_table(log: pd.DataFrame) -> pd.DataFrame:
    """One row per message: type, sender, attempts, receivers, first send and receive, latency."""
    if MSG_ID not in log.columns:
        return pd.DataFrame()
    roles = message_roles(log)
    events = log.assign(_role=roles)[roles.notna().to_numpy(bool) & log[MSG_ID].notna()]
    if events.empty:
        return pd.DataFrame()
    keys = [CASE, MSG_ID] if CASE in events.columns else [MSG_ID]
    sends = events[events["_role"] == SEND]
    receives = events[events["_role"] == RECEIVE]
    table = events.groupby(keys, sort=True).agg(first_event=(TIMESTAMP, "min"))
    table[TYPE] = _types(sends, receives, keys).reindex(table.index)
    sends = _sends_of_type(sends, table[TYPE], keys)
    table["sender"] = _first(sends, keys, ROBOT).reindex(table.index)
    table["sent_at"] = sends.groupby(keys)[TIMESTAMP].min().reindex(table.index)
    table["received_at"] = receives.groupby(keys)[TIMESTAMP].min().reindex(table.index)
    table["attempts"] = _attempts(sends, keys).reindex(table.index).fillna(0).astype(int)
    table["receivers"] = _distinct(receives, keys, ROBOT).reindex(table.index).fillna(0)
    table["sent"] = table["attempts"] > 0
    table["received"] = table["received_at"].notna()
    table["lost"] = table["sent"] & ~table["received"]
    table["resends"] = (table["attempts"] - 1).clip(lower=0)
    table["latency"] = (table["received_at"] - table["sent_at"]).dt.total_seconds()
    table["receivers"] = table["receivers"].astype(int)
    return table.drop(columns="first_event").reset_index()


def _types(sends: pd.DataFrame, receives: pd.DataFrame, keys: list[str]) -> pd.Series:
    # An activity that also sends, such as a selection that starts a message, does not name
    # it when the message activity itself (``x!``) is there.
    marked = sends[ACTIVITY].astype("string").str.endswith("!").fillna(False).to_numpy(bool)
    named = _first(sends[marked], keys, ACTIVITY).combine_first(_first(sends, keys, ACTIVITY))
    from_receive = _first(receives, keys, ACTIVITY).map(_type_of)
    return named.combine_first(from_receive)


def _sends_of_type(sends: pd.DataFrame, types: pd.Series, keys: list[str]) -> pd.DataFrame:
    """The sends performed by the activity a message is named after (the attempts)."""
    named = types.rename("_type").reset_index()
    joined = sends.merge(named, on=keys, how="left")
    return joined[joined[ACTIVITY].astype(object) == joined["_type"].astype(object)]


def _type_of(activity: str) -> str:
    return activity[:-1] + "!" if activity.endswith("?") else activity


def _first(events: pd.DataFrame, keys: list[str], column: str) -> pd.Series:
    if column not in events.columns:
        return pd.Series(dtype=object)
    ordered = events.sort_values(TIMESTAMP, kind="stable")
    return ordered.groupby(keys)[column].first().astype(object)


def _distinct(events: pd.DataFrame, keys: list[str], column: str) -> pd.Series:
    if column not in events.columns:
        return events.groupby(keys).size().clip(upper=1)
    return events.groupby(keys)[column].nunique()


def _involving(log: pd.DataFrame, messages: pd.DataFrame, robot: str) -> pd.Series:
    """Which messages ``robot`` sent or received."""
    if ROBOT not in log.columns:
        return pd.Series(False, index=messages.index)
    keys = [CASE, MSG_ID] if CASE in messages.columns else [MSG_ID]
    mine = log.loc[log[ROBOT].astype("string").eq(robot).fillna(False).to_numpy(bool), keys]
    involved = pd.MultiIndex.from_frame(mine.dropna().astype(str).drop_duplicates())
    return pd.Series(
        pd.MultiIndex.from_frame(messages[keys].astype(str)).isin(involved), index=messages.index
    )


def _attempts(sends: pd.DataFrame, keys: list[str]) -> pd.Series:
    """Sends per message: starts and completes of one attempt count once; instant events
    (lifecycle none or missing) count each."""
    if LIFECYCLE not in sends.columns:
        return sends.groupby(keys).size()
    lifecycle = sends[LIFECYCLE].astype("string").fillna("none").str.lower()
    counts = (
        pd.DataFrame(
            {
                "start": lifecycle.eq(START),
                "complete": lifecycle.eq(COMPLETE),
                "instant": ~lifecycle.isin([START, COMPLETE]),
            }
        )
        .groupby([sends[k] for k in keys])
        .sum()
    )
    return counts[["start", "complete"]].max(axis=1) + counts["instant"]


def _by_type(messages: pd.DataFrame) -> pd.DataFrame:
    grouped = messages.groupby(TYPE, sort=True)
    table = grouped.agg(
        sent=("sent", "sum"),
        received=("received", "sum"),
        lost=("lost", "sum"),
        resends=("resends", "sum"),
        latency_mean=("latency", "mean"),
        latency_median=("latency", "median"),
        latency_max=("latency", "max"),
        receivers_mean=("receivers", "mean"),
    )
    table["loss_rate"] = table["lost"] / table["sent"].where(table["sent"] > 0)
    return table.reset_index()


def _figure(types: pd.DataFrame):
    from plotly.subplots import make_subplots

    figure = make_subplots(
        rows=1, cols=2, subplot_titles=("Messages", "Latency, first send to first receive (s)")
    )
    for column, colour in (("received", "#2ca02c"), ("lost", "#d62728"), ("resends", "#ff7f0e")):
        figure.add_bar(
            x=types[TYPE], y=types[column], name=column, marker_color=colour, row=1, col=1
        )
    for column, colour in (("latency_mean", "#1f77b4"), ("latency_median", "#9467bd")):
        figure.add_bar(
            x=types[TYPE],
            y=types[column],
            name=column.replace("_", " "),
            marker_color=colour,
            row=1,
            col=2,
        )
    figure.update_layout(barmode="group", title="Inter-robot communication")
    return figure
