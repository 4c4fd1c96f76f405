"""Inter-robot communication: who talks to whom, what got lost, delayed or resent (thesis 7.2.2).

A message is one ``msg_id`` in a case. Its sends are the events whose role is send
(``msg_role`` or an activity ending in ``!``), its receives those whose role is receive (or
``?``). A message type is named after its send activity (a message nobody was seen sending is
named after its receive activity with ``?`` turned into ``!``). Its sender is ``msg_sender``
where the log has it, else the robot of its sends; its receivers the robots of its receives,
else ``msg_receiver``, else the one robot that received every other message of its sender and
type, else ``unknown``. A channel is a sender -> receiver pair. Per message:

- sent: it has at least one send; received: at least one receive;
- lost or not observed as received: sent, never received. Only a log that tags receives of
  its type can say it was lost: a message type is *receive-tagged* when some receive of that
  type appears in the log (and, for a message whose receiver is named, some receive of that
  type by that receiver). A message of a type without receive tags may well have arrived (a
  skill that consumes a message leaves no receive tag): it is ``unobserved``, never ``lost``,
  and the summary names those types (``untagged_types``);
- attempts: how many times it was sent under its id (the send activity's starts, or its events
  when the log has no lifecycle);
- resends: attempts - 1 (``resends_same_id``), plus one when the sender sent it again under a
  new id (``resends_new_id``): a later message of the same case and sender, sent while this
  one had no answer, to the same receiver (of any type: a resend may change its type), or of
  the same type where either receiver is unknown (a message nobody received may have been
  meant for any robot that received its sender's other messages of its type). An answer is a
  message from its receiver (from anyone, when its receiver is unknown) that reached its
  sender: when it was received, or sent where its type has no receive tags; a lost answer
  answers nothing. A receive of it answers it too, unless every robot that received it
  answered and every answer was lost (its sender heard nothing back). At one moment receives
  come before sends, so a robot's reply to a question it just heard is no resend of its
  earlier reply. Each resend names the message it repeats (``repeats``; the repeated one
  names it in ``resent_as``); a message is repeated at most once (a chain of resends repeats
  one after the other). The payload is a hint, never a requirement: when several unanswered
  messages could be the repeated one, the one with the same payload wins, else the latest
  (payloads are often constant or carry a stamp, so they neither make nor break one); only
  where a sender's payloads of a type name their content (one of them was sent twice) is a
  message of that type with another payload the next task rather than a resend;
- latency: from its first send to its first receive (per receiver on the channels);
- delayed: see :mod:`robotale.enhancement.delays` (an explicit threshold, or the slow mode of
  a two-mode latency distribution per channel: sender, receiver and type; the channels table
  says from which latency, ``delayed_from``); ``delay_rule`` states the rule used.

For every lost message the ``lost`` table says what its sender did next, whether it was resent
and got through, and how much later its case ended than the median case without a lost message.
"""

from __future__ import annotations

import numpy as np
import pandas as pd

from robotale.enhancement.context import LogAnalysis, analysis_of, row_keys, sorted_distinct
from robotale.enhancement.delays import delay_rule, delayed, slow_mode_starts
from robotale.enhancement.effects import compare_cases
from robotale.enhancement.followed import what_followed
from robotale.enhancement.performance import finished_instances, shared_cases
from robotale.enhancement.result import Figures, Perspective, focus_label, no_data
from robotale.eventlog.schema import (
    ACTIVITY,
    CASE,
    COMPLETE,
    LIFECYCLE,
    MSG_ID,
    MSG_PAYLOAD,
    MSG_RECEIVER,
    MSG_ROLE,
    MSG_SENDER,
    RECEIVE,
    ROBOT,
    SEND,
    START,
    TIMESTAMP,
    message_roles,
)

TYPE = "message_type"
#: a message's number (its row in the message table): one integer key instead of case and id,
#: so each per-message step groups and looks up integers rather than pairs of texts
MESSAGE = "_message"
UNKNOWN = "unknown"
CHANNEL = ["sender", "receiver", TYPE]


def communication_perspective(
    log: pd.DataFrame | LogAnalysis,
    *,
    activity: str | None = None,
    robot: str | None = None,
    delay_threshold: float | None = None,
    following: int = 3,
) -> Perspective:
    """Per message type and per channel: sent, received, lost, delayed, resent and latency;
    every message; every lost message with its consequence; with a bar chart.

    With ``activity`` (a send ``x!`` or receive ``x?`` activity) only the messages of that
    type; with ``robot`` only the messages that robot sent or received.
    """
    analysis = analysis_of(log)
    log = analysis.log
    messages, deliveries = shared_message_tables(analysis, delay_threshold)
    if messages.empty:
        return no_data("communication", "the log has no messages (no events with a msg_id).")
    keep = pd.Series(True, index=messages.index)
    if activity is not None:
        keep &= messages[TYPE] == _type_of(activity)
    if robot is not None:
        keep &= _involving(log, messages, robot)
    if not keep.any():
        return no_data("communication", f"no message involves {focus_label(activity, robot)}.")
    lost, lost_effect = lost_messages(analysis, messages, following)
    messages = messages[keep]
    deliveries = deliveries.merge(messages[_keys(messages)], on=_keys(messages))
    lost = lost.merge(messages[_keys(messages)], on=_keys(messages))
    types, channels = _by_type(messages, deliveries), _by_channel(deliveries)
    if delay_threshold is None:
        starts = slow_mode_starts(deliveries["latency"], _channel_of(deliveries))
        channels["delayed_from"] = _channel_of(channels).map(starts).astype(float)
    else:
        channels["delayed_from"] = float(delay_threshold)
    summary = _summary(messages, channels, lost_effect)
    summary["delay_rule"] = delay_rule(delay_threshold)
    return Perspective(
        name="communication",
        tables={"message_types": types, "channels": channels, "messages": messages, "lost": lost},
        figures=Figures({"messages": lambda: _figure(types)}),
        summary=summary,
    )


def message_table(log: pd.DataFrame) -> pd.DataFrame:
    """One row per message: type, sender, receiver(s), attempts, first send and receive,
    latency, whether it was lost, delayed or resent."""
    return message_tables(log)[0]


def shared_message_tables(
    analysis: LogAnalysis, delay_threshold: float | None = None
) -> tuple[pd.DataFrame, pd.DataFrame]:
    """:func:`message_tables` of the analysed log, built once per analysis and threshold."""
    return analysis.shared(
        ("messages", delay_threshold), lambda: message_tables(analysis.log, delay_threshold)
    )


def message_tables(
    log: pd.DataFrame, delay_threshold: float | None = None
) -> tuple[pd.DataFrame, pd.DataFrame]:
    """The messages, and their deliveries: one row per message and receiver (a message nobody
    received has one, to the receiver it was meant for or ``unknown``)."""
    core = _message_core(log)
    if core is None:
        return pd.DataFrame(), pd.DataFrame()
    table, events, sends, receives = core
    ids = [MESSAGE]
    if MSG_PAYLOAD in events.columns:
        payload = _first(events, ids, MSG_PAYLOAD).reindex(table.index)
        table.insert(table.columns.get_loc("sent_at"), "payload", payload)
    table["attempts"] = _attempts(sends, ids).reindex(table.index).fillna(0).astype(int)
    table["receivers"] = _distinct(receives, ids, ROBOT).reindex(table.index).fillna(0)
    table["receivers"] = table["receivers"].astype(int)
    table["sent"] = table["attempts"] > 0
    table["received"] = table["received_at"].notna()
    table["lost"] = table["sent"] & ~table["received"]
    table["latency"] = (table["received_at"] - table["sent_at"]).dt.total_seconds()
    table = table.drop(columns="first_event")
    numbered = table.assign(**{MESSAGE: np.arange(len(table))})
    deliveries = _deliveries(numbered, events, receives, ids)
    table["receiver"] = _lookup(numbered, ids, _joined(deliveries, ids, "receiver"))
    deliveries["delayed"] = delayed(deliveries["latency"], _channel_of(deliveries), delay_threshold)
    late = deliveries.groupby(MESSAGE)["delayed"].any()
    table["delayed"] = _lookup(numbered, ids, late).fillna(False).astype(bool)
    _split_lost(table, deliveries, numbered, ids)
    keys = _keys(table)
    return _with_resends(table, deliveries), _with_keys(deliveries, table, keys)


def _with_keys(rows: pd.DataFrame, table: pd.DataFrame, keys: list[str]) -> pd.DataFrame:
    """``rows`` with their message's case and id (``keys``) in place of its number."""
    named = table[keys].iloc[rows[MESSAGE].to_numpy()].reset_index(drop=True)
    return pd.concat([named, rows.drop(columns=MESSAGE).reset_index(drop=True)], axis=1)


def shared_latencies(analysis: LogAnalysis) -> pd.DataFrame:
    """Per message (rows as in :func:`message_table`): its type, sender and ``latency``, from
    the analysis' message table when it has one, else from the little that needs."""
    # the message table of any delay threshold: latencies do not depend on it
    built = [k for k in analysis.built() if isinstance(k, tuple) and k[:1] == ("messages",)]
    if built:
        return shared_message_tables(analysis, built[0][1])[0]

    def build() -> pd.DataFrame:
        core = _message_core(analysis.log)
        if core is None:
            return pd.DataFrame()
        table = core[0]
        table["latency"] = (table["received_at"] - table["sent_at"]).dt.total_seconds()
        return table

    return analysis.shared("latencies", build)


def _message_core(log: pd.DataFrame):
    """The message events, the sends performed by the activity each message is named after,
    the receives (each with its message's number, ``_message``), and per message (in case and
    id order, its number the row): case, id, type, sender, first send and first receive;
    ``None`` when the log has no messages."""
    events = _message_events(log)
    if events.empty:
        return None
    grouped = events.groupby(_keys(events), sort=True)  # the one grouping by case and id
    table = grouped.agg(first_event=(TIMESTAMP, "min")).reset_index()
    number = grouped.ngroup()
    known = number.notna().to_numpy()  # an event without a case belongs to no message
    events = events[known].assign(**{MESSAGE: number[known].astype(np.int64)})
    ids = [MESSAGE]
    sends = events[events["_role"] == SEND]
    receives = events[events["_role"] == RECEIVE]
    table[TYPE] = _types(sends, receives, ids).reindex(table.index)
    sends = _sends_of_type(sends, table[TYPE])
    table["sender"] = _sender(events, sends, ids).reindex(table.index)
    table["sent_at"] = sends.groupby(MESSAGE)[TIMESTAMP].min().reindex(table.index)
    table["received_at"] = receives.groupby(MESSAGE)[TIMESTAMP].min().reindex(table.index)
    return table, events, sends, receives


def lost_messages(
    log: pd.DataFrame | LogAnalysis, messages: pd.DataFrame, following: int = 3
) -> tuple[pd.DataFrame, dict]:
    """Every lost message with what its sender did next (``then``), whether it was resent and
    the resend got through, seconds from its send to its case's end, and how much later its
    case ended than the median case without a lost message (``ended_later_by``). With them,
    how much longer the cases with a lost message take than the others (mean, p-value)."""
    lost = messages[messages["lost"]]
    columns = [*_keys(messages), TYPE, "sender", "receiver", "sent_at", "resent_as", "recovered"]
    lost = lost[[c for c in columns if c in lost.columns]].reset_index(drop=True)
    analysis = analysis_of(log)
    instances = finished_instances(analysis)
    if lost.empty or instances.empty or CASE not in lost.columns:
        return lost.assign(then=pd.Series(dtype=object)), {}
    lost["then"] = _what_followed(lost, instances, following)
    cases = shared_cases(analysis).set_index(CASE)
    ends = cases["end"].reindex(lost[CASE]).to_numpy()
    lost["until_end"] = (pd.Series(ends) - lost["sent_at"]).dt.total_seconds()
    calm = cases.loc[~cases.index.isin(lost[CASE]), "duration"]
    duration = cases["duration"].reindex(lost[CASE]).to_numpy()
    lost["ended_later_by"] = duration - (calm.median() if len(calm) else np.nan)
    effect = compare_cases(lost.assign(_lost=True), "_lost", cases["duration"])
    return lost, _lost_effect(effect)


#: the columns the message tables read: a wide log's other columns are not copied along
MESSAGE_COLUMNS = (
    CASE,
    MSG_ID,
    ACTIVITY,
    TIMESTAMP,
    LIFECYCLE,
    ROBOT,
    MSG_ROLE,
    MSG_SENDER,
    MSG_RECEIVER,
    MSG_PAYLOAD,
)


def _message_events(log: pd.DataFrame) -> pd.DataFrame:
    if MSG_ID not in log.columns:
        return pd.DataFrame()
    with_id = np.flatnonzero(log[MSG_ID].notna().to_numpy(bool))
    # the roles of the rows with an id first, so the wanted rows and columns are copied once
    roles = event_roles(_rows(log, with_id, (ACTIVITY, MSG_ROLE)))
    role = roles.notna().to_numpy(bool)
    events = _rows(log, with_id[role], MESSAGE_COLUMNS)
    return events.assign(_role=roles.to_numpy(object)[role])


def _rows(log: pd.DataFrame, rows: np.ndarray, wanted: tuple[str, ...]) -> pd.DataFrame:
    """The ``rows`` (positions) of the log's columns named in ``wanted``, in one copy."""
    return log.iloc[rows, [i for i, c in enumerate(log.columns) if c in wanted]]


def event_roles(events: pd.DataFrame) -> pd.Series:
    """:func:`~robotale.eventlog.schema.message_roles` per event, worked out once per distinct
    activity and ``msg_role`` (a log repeats a few names many times)."""
    combination = np.zeros(len(events), dtype=np.int64)
    for column in (c for c in (ACTIVITY, MSG_ROLE) if c in events.columns):
        codes, uniques = pd.factorize(events[column], use_na_sentinel=False)
        combination = combination * (len(uniques) + 1) + codes
    combination = pd.factorize(combination)[0]  # numbered 0, 1, ... by first appearance
    first = pd.Series(combination).drop_duplicates()
    roles = np.empty(len(first), dtype=object)
    roles[first.to_numpy()] = message_roles(events.iloc[first.index]).to_numpy(object)
    return pd.Series(roles[combination], index=events.index, dtype=object, name=MSG_ROLE)


def _ends_with(values: pd.Series, suffix: str) -> np.ndarray:
    """Which ``values`` end in ``suffix`` (missing ones do not), tested once per distinct
    value."""
    codes, uniques = pd.factorize(values.astype(object))
    ends = pd.Series(uniques, dtype="string").str.endswith(suffix).fillna(False)
    return np.append(ends.to_numpy(bool), False)[codes]


def _keys(frame: pd.DataFrame) -> list[str]:
    return [CASE, MSG_ID] if CASE in frame.columns else [MSG_ID]


def _types(sends: pd.DataFrame, receives: pd.DataFrame, keys: list[str]) -> pd.Series:
    # An activity that also sends, such as a selection that starts a message, does not name
    # it when the message activity itself (``x!``) is there.
    marked = _ends_with(sends[ACTIVITY], "!")
    named = _first(sends[marked], keys, ACTIVITY).combine_first(_first(sends, keys, ACTIVITY))
    received = _first(receives, keys, ACTIVITY)
    codes, names = pd.factorize(received, use_na_sentinel=False)  # a few names, many messages
    from_receive = pd.Series(names.map(_type_of).to_numpy(object)[codes], index=received.index)
    return named.combine_first(from_receive)


def _sends_of_type(sends: pd.DataFrame, types: pd.Series) -> pd.DataFrame:
    """The sends performed by the activity a message is named after (the attempts)."""
    named = pd.Series(types.to_numpy(object)[sends[MESSAGE].to_numpy()], index=sends.index)
    return sends[sends[ACTIVITY].astype(object) == named]


def _sender(events: pd.DataFrame, sends: pd.DataFrame, keys: list[str]) -> pd.Series:
    stated = _first(events, keys, MSG_SENDER) if MSG_SENDER in events.columns else None
    seen = _first(sends, keys, ROBOT)
    return seen if stated is None else stated.combine_first(seen)


def _deliveries(
    table: pd.DataFrame, events: pd.DataFrame, receives: pd.DataFrame, keys: list[str]
) -> pd.DataFrame:
    """One row per message and receiver, with the first receive by that receiver."""
    base = table[[*keys, TYPE, "sender", "sent_at"]]
    receiver = _receiving_robot(receives)
    if receiver is not None and not receives.empty:
        receives = receives.assign(receiver=receiver).dropna(subset=["receiver"])
        seen = receives.groupby([*keys, "receiver"])[TIMESTAMP].min()
        seen = seen.rename("received_at").reset_index()
    else:
        seen = pd.DataFrame(columns=[*keys, "receiver", "received_at"])
    reached = base.merge(seen, on=keys)
    missing = base[~_in(base, reached, keys)]
    # a missing time of the received times' own type: times of mixed types would be parsed
    # one by one below
    unknown = reached["received_at"].dtype if len(reached) else object
    missing = missing.assign(received_at=pd.Series(pd.NaT, index=missing.index, dtype=unknown))
    missing["receiver"] = _meant_for(missing, events, reached, keys)
    deliveries = pd.concat([reached, missing], ignore_index=True)
    deliveries["received_at"] = pd.to_datetime(deliveries["received_at"], utc=True)
    latency = deliveries["received_at"] - deliveries["sent_at"]
    deliveries["latency"] = latency.dt.total_seconds()
    deliveries["received"] = deliveries["received_at"].notna()
    deliveries["lost"] = deliveries["sent_at"].notna() & ~deliveries["received"]
    return deliveries


def _receiving_robot(receives: pd.DataFrame) -> pd.Series | None:
    """Per receive event, who received: ``msg_receiver`` where set, else the event's robot."""
    stated = receives[MSG_RECEIVER].astype(object) if MSG_RECEIVER in receives.columns else None
    robot = receives[ROBOT].astype(object) if ROBOT in receives.columns else None
    if stated is None or robot is None:
        return stated if robot is None else robot
    return stated.combine_first(robot)


def _meant_for(missing, events, reached, keys) -> np.ndarray:
    """Who an unreceived message was for: ``msg_receiver``, else the one robot that received
    every other message of its sender and type, else ``unknown``."""
    if missing.empty:
        return np.array([], dtype=object)
    stated = pd.Series(np.nan, index=missing.index, dtype=object)
    if MSG_RECEIVER in events.columns:
        stated = _lookup(missing, keys, _first(events, keys, MSG_RECEIVER))
    receivers = reached.groupby(["sender", TYPE])["receiver"]
    usual = receivers.first().astype(object).where(receivers.nunique() == 1, np.nan)
    guessed = pd.Series(
        usual.reindex(pd.MultiIndex.from_frame(missing[["sender", TYPE]])).to_numpy(),
        index=missing.index,
    )
    return stated.combine_first(guessed).fillna(UNKNOWN).to_numpy(object)


def _split_lost(table, deliveries, numbered, ids) -> None:
    """An unreceived delivery is lost only where the log tags receives of its type (by its
    receiver, when named); else it is ``unobserved``: it may have arrived untagged."""
    tagged_types = set(table.loc[table["received"], TYPE].dropna())
    receiver = deliveries["receiver"].astype(object)
    pairs = _pairs_in(deliveries[TYPE], receiver, deliveries["received"].to_numpy(bool))
    tagged = deliveries[TYPE].isin(tagged_types) & (receiver.eq(UNKNOWN) | pairs)
    # a message received by a robot the log does not name has a delivery without a receiver
    arrived = table["received"].to_numpy(bool)[deliveries[MESSAGE].to_numpy()]
    missing = deliveries["sent_at"].notna() & ~deliveries["received"] & ~arrived
    deliveries["lost"] = missing & tagged
    deliveries["unobserved"] = missing & ~tagged
    lost = deliveries.groupby(MESSAGE)["lost"].any()
    lost = _lookup(numbered, ids, lost).fillna(False).astype(bool)
    table["lost"] = table["lost"] & lost
    table["unobserved"] = table["sent"] & ~table["received"] & ~table["lost"]


def _pairs_in(first: pd.Series, second: pd.Series, chosen: np.ndarray) -> np.ndarray:
    """Which rows' (``first``, ``second``) pair is also the pair of a ``chosen`` row."""
    keys = row_keys([first, second], [])
    if keys is None:  # a missing value: matched as an index of pairs matches it
        known = pd.MultiIndex.from_arrays([first[chosen], second[chosen]])
        return pd.MultiIndex.from_arrays([first, second]).isin(known)
    return np.isin(keys[0], keys[0][chosen])


def _channel_of(rows: pd.DataFrame) -> pd.Series:
    """Each row's channel (sender, receiver and type) as one text, to group by."""
    # the text is made once per distinct channel (a log has a few, with many messages each)
    combination = np.zeros(len(rows), dtype=np.int64)
    for column in CHANNEL:
        codes, uniques = pd.factorize(rows[column], use_na_sentinel=False)
        combination = combination * (len(uniques) + 1) + codes
    _, firsts, codes = np.unique(combination, return_index=True, return_inverse=True)
    distinct = rows.iloc[firsts]
    parts = [distinct[c].astype(object).where(distinct[c].notna(), "").astype(str) for c in CHANNEL]
    texts = (parts[0] + "\x1f" + parts[1] + "\x1f" + parts[2]).to_numpy(object)
    return pd.Series(texts[codes.reshape(-1)], index=rows.index, dtype=object)


def untagged_types(messages: pd.DataFrame) -> list[str]:
    """The message types sent in the log none of whose receives it tags: whether their
    messages arrived is unknown."""
    sent = messages[messages["sent"]]
    received = set(messages.loc[messages["received"], TYPE])
    return sorted({str(t) for t in sent[TYPE].dropna() if t not in received})


def _with_resends(table: pd.DataFrame, deliveries: pd.DataFrame) -> pd.DataFrame:
    """Adds which message each message was sent again as (``resent_as``) and repeats
    (``repeats``), the resends by id reuse and by new id, and ``recovered``: lost, but a
    resend got through."""
    resent_as, repeats = _repeated(table, deliveries)
    table["resent_as"] = resent_as
    table["repeats"] = repeats
    table["resends_same_id"] = (table["attempts"] - 1).clip(lower=0)
    table["resends_new_id"] = table["repeats"].notna().astype(int)
    table["resends"] = table["resends_same_id"] + table["resends_new_id"]
    ids = pd.Series(np.arange(len(table)), index=table.index)
    resend_row = _resend_rows(table, ids)
    got_through = table["received"].to_numpy(bool)[np.maximum(resend_row, 0)] & (resend_row >= 0)
    table["recovered"] = table["lost"].to_numpy(bool) & got_through
    return table


def _resend_rows(table: pd.DataFrame, ids: pd.Series) -> np.ndarray:
    """Per message, the row of the message it was resent as (-1: none)."""
    # (case, id) numbered as one integer: the table's ids and the ids resent as, coded together
    n = len(table)
    codes, names = pd.factorize(
        pd.concat([table[MSG_ID].astype(object), table["resent_as"].astype(object)],
                  ignore_index=True)
    )  # fmt: skip
    cases = pd.factorize(table[CASE])[0] if CASE in table.columns else np.zeros(n, np.int64)
    keys = np.tile(cases.astype(np.int64), 2) * (len(names) + 1) + codes
    found = pd.Index(keys[:n]).get_indexer(keys[n:])
    found[(codes[n:] < 0) | (np.tile(cases, 2)[n:] < 0)] = -1  # no id resent as, or no case
    return np.where(found >= 0, ids.to_numpy(np.int64)[np.maximum(found, 0)], -1)


def _repeated(table: pd.DataFrame, deliveries: pd.DataFrame) -> tuple[pd.Series, pd.Series]:
    """Per message, the id of the message that repeated it and of the one it repeats (see
    the module: same case and sender, same receiver or type, sent while it had no answer)."""
    n = len(table)
    resent_as = np.full(n, None, dtype=object)
    repeats = np.full(n, None, dtype=object)
    sent = table["sent"].to_numpy(bool) & table["sent_at"].notna().to_numpy(bool)
    if not sent.any():
        return pd.Series(resent_as, index=table.index), pd.Series(repeats, index=table.index)
    cases = table[CASE].astype(object).tolist() if CASE in table.columns else [0] * n
    # times as integers; a message never received is received never (the largest time)
    sent_at = _integer_times(table["sent_at"])
    never = np.iinfo(np.int64).max
    received = table["received"].to_numpy(bool)
    received_at = np.where(received, _integer_times(table["received_at"]), never)
    senders = table["sender"].astype(object).tolist()
    types = table[TYPE].astype(object).tolist()
    ids = table[MSG_ID].astype(object).tolist()
    receivers = _possible_receivers(table)
    payloads = table["payload"].astype(object).tolist() if "payload" in table else None
    named = _naming_payloads(table)
    rows, robots, kinds = _conversation(sent, sent_at, deliveries)
    sent_at, received_at = sent_at.tolist(), received_at.tolist()
    # case -> robot -> the robot's unanswered messages (rows), oldest first; a message
    # received stays unanswered where what its receiver sent back was lost
    waiting: dict[object, dict[object, list[int]]] = {}
    unheard: dict[int, set] = {}  # message row -> the robots whose answers to it were lost
    for row, robot, kind in zip(rows, robots, kinds, strict=True):
        in_case = waiting.get(cases[row])
        if in_case is None:  # not ``setdefault``: that makes a new dict at every step
            in_case = waiting[cases[row]] = {}
        if kind == ARRIVED:  # ``row`` reached ``robot``: an answer to its messages
            if isinstance(robot, str) and robot != UNKNOWN:  # most steps: one named robot
                theirs = in_case.get(robot)
                if theirs and robot != (sender := senders[row]):
                    # :func:`_answered`, written out: the walk's most frequent step
                    theirs[:] = [a for a in theirs if receivers[a] and sender not in receivers[a]]
            else:
                _answer(in_case, senders[row], robot, receivers)
            continue
        if kind == LOST:  # ``row``, meant for ``robot``, never reached it
            _unheard(in_case, senders[row], robot, receivers, received_at, sent_at[row], unheard)
            continue
        sender, at = senders[row], sent_at[row]
        mine = in_case.get(sender)
        if mine is None:
            mine = in_case[sender] = []
        if mine:
            mine[:] = [a for a in mine if received_at[a] > at or unheard.get(a) == receivers[a]]
        if not mine:  # most sends: nothing of the sender's is waiting for an answer
            mine.append(row)
            continue
        candidates = [
            a
            for a in mine
            if _may_repeat(a, row, types, receivers)
            and not (named[row] and _other_payload(payloads, a, row, types))
        ]
        if candidates:
            same = [
                a
                for a in candidates
                if payloads is not None and _same_payload(payloads[a], payloads[row])
            ]
            chosen = (same or candidates)[-1]
            mine.remove(chosen)
            resent_as[chosen], repeats[row] = ids[row], ids[chosen]
        mine.append(row)
    return pd.Series(resent_as, index=table.index), pd.Series(repeats, index=table.index)


#: the steps of a conversation (:func:`_conversation`), in their order at one instant
ARRIVED, SENT, LOST = 0, 1, 2


def _conversation(
    sent: np.ndarray, sent_at: np.ndarray, deliveries: pd.DataFrame
) -> tuple[list[int], list, list[int]]:
    """The steps of a log's conversations in time order, as (message row, robot, step): its
    sends (the robot None); its arrivals: a message its receiver got (where the log tags it)
    or may have got (sent, of a type whose receives the log does not tag: at its send); and
    its losses, at the send, with the robot it was meant for. At one instant arrivals come
    first (what a robot sends as it hears something answers what it heard), losses last (a
    reply lost at once still replies to what was sent then)."""
    message = deliveries[MESSAGE].to_numpy(np.int64)
    got = deliveries["received"].to_numpy(bool)
    unobserved = deliveries["unobserved"].to_numpy(bool) & ~got
    lost = deliveries["lost"].to_numpy(bool) & ~got & ~unobserved
    arrived = got | unobserved
    when = np.where(got, _integer_times(deliveries["received_at"]), sent_at[message])
    sends = np.flatnonzero(sent)
    steps = np.concatenate([arrived, lost])
    times = np.concatenate([when, sent_at[message], sent_at[sends]])
    kinds = np.concatenate(
        [np.full(len(message), ARRIVED), np.full(len(message), LOST), np.full(len(sends), SENT)]
    )
    keep = np.concatenate([steps, np.ones(len(sends), bool)])
    order = np.flatnonzero(keep)[np.lexsort((kinds[keep], times[keep]))]
    robots = deliveries["receiver"].astype(object).to_numpy()
    none = np.full(len(sends), None, dtype=object)
    rows = np.concatenate([message, message, sends])[order].tolist()
    by = np.concatenate([robots, robots, none])[order].tolist()
    return rows, by, kinds[order].tolist()


def _may_repeat(earlier: int, later: int, types, receivers: list[frozenset]) -> bool:
    """Whether ``later`` may repeat ``earlier`` by their ends and types alone: the same
    receiver, whatever the type; or the same type where a receiver is unknown (a message to
    another known robot is not a resend of it)."""
    mine, theirs = receivers[earlier], receivers[later]
    if mine and theirs:
        return bool(mine & theirs)
    return types[earlier] == types[later]


def _possible_receivers(table: pd.DataFrame) -> list[frozenset]:
    """Per message, the robots it went to; for one no robot is known to have received, the
    robots that received its sender's other messages of its type (a message nobody got may
    have been meant for any of them), else none known."""
    # each distinct receiver text split once (a log has a few, on many messages)
    codes, uniques = pd.factorize(_as_values(table["receiver"]), use_na_sentinel=False)
    sets = [_receiver_set(r) for r in uniques.tolist()]
    if table["sender"].isna().any() or table[TYPE].isna().any():
        # a missing sender or type is a key of its own object: worked out per message
        return _usual_receivers(table["sender"].tolist(), table[TYPE].tolist(), sets, codes)
    # worked out once per distinct sender, type and receiver (a log has a few, many times)
    pair = row_keys([table["sender"], table[TYPE]], [])[0]  # no value missing: never None
    combination = pd.factorize(pair * (len(sets) + 1) + codes)[0]
    firsts = pd.Series(combination).drop_duplicates().index.to_numpy()
    found = _usual_receivers(pair[firsts].tolist(), [None] * len(firsts), sets, codes[firsts])
    return [found[c] for c in combination.tolist()]


def _usual_receivers(senders: list, kinds: list, sets: list[frozenset], codes) -> list[frozenset]:
    """Per message (its sender, type and receiver's code in ``sets``), its receivers, else the
    receivers of its sender's messages of its type."""
    named = [sets[c] for c in codes.tolist()]
    usual: dict[tuple, frozenset] = {}
    for sender, kind, robots in zip(senders, kinds, named, strict=True):
        if robots:
            usual[(sender, kind)] = usual.get((sender, kind), frozenset()) | robots
    pairs = zip(senders, kinds, strict=True)
    return [robots or usual.get(pair, robots) for pair, robots in zip(pairs, named, strict=True)]


def _naming_payloads(table: pd.DataFrame) -> list[bool]:
    """Per message, whether the payloads of its sender's messages of its type name their
    content: some payload was sent more than once. Payloads that are all different (a stamp,
    a counter) say nothing about a resend."""
    if "payload" not in table:
        return [False] * len(table)
    frame = pd.DataFrame(
        {
            "sender": table["sender"].astype(object).to_numpy(),
            "type": table[TYPE].astype(object).to_numpy(),
            "payload": table["payload"].astype(object).to_numpy(),
        }
    )
    frame["again"] = frame["payload"].notna() & frame.duplicated(keep=False)
    again = frame.groupby(["sender", "type"], dropna=False)["again"].transform("any")
    return again.to_numpy(bool).tolist()


def _as_values(column: pd.Series) -> pd.Series:
    """A text column as it is (factorised at once), another as Python objects."""
    return column if isinstance(column.dtype, pd.StringDtype) else column.astype(object)


def _other_payload(payloads, earlier: int, later: int, types) -> bool:
    """Whether ``later`` carries other content than ``earlier`` of its type (both payloads
    given and different): the next task, not the same one again."""
    if payloads is None or types[earlier] != types[later]:
        return False
    one, two = payloads[earlier], payloads[later]
    return isinstance(one, str) and isinstance(two, str) and one != two


def _same_payload(earlier, later) -> bool:
    return isinstance(earlier, str) and isinstance(later, str) and earlier == later


def _answer(waiting: dict, sender, receiver, receivers: list[frozenset]) -> None:
    """A message from ``sender`` reached ``receiver`` (``unknown``: any robot but the
    sender): it answers the receiver's unanswered messages of its case sent to ``sender``
    (or to nobody known)."""
    for theirs in _waiting_for(waiting, sender, receiver):
        if theirs:
            _answered(theirs, sender, receivers)


def _answered(theirs: list[int], sender, receivers: list[frozenset]) -> None:
    """Drops from ``theirs`` the messages a message from ``sender`` answers: those sent to
    ``sender`` (or to nobody known)."""
    theirs[:] = [a for a in theirs if receivers[a] and sender not in receivers[a]]


def _waiting_for(waiting: dict, sender, receiver) -> list[list[int]]:
    """The unanswered messages of ``receiver`` (``unknown``: of every robot but ``sender``),
    one list per robot."""
    if isinstance(receiver, str) and receiver != UNKNOWN:
        theirs = waiting.get(receiver)
        return [] if theirs is None or receiver == sender else [theirs]
    return [theirs for other, theirs in waiting.items() if other != sender]


def _unheard(
    waiting: dict, sender, receiver, receivers, received_at, at: int, unheard: dict[int, set]
) -> None:
    """A message from ``sender`` to ``receiver`` (``unknown``: any robot but the sender) was
    lost at ``at``: the receiver's messages to ``sender`` that ``sender`` had received by then
    lost an answer. One whose every receiver's answer was lost is unanswered still, though
    received: its sender heard nothing back where everyone answered."""
    for theirs in _waiting_for(waiting, sender, receiver):
        for a in theirs:
            if received_at[a] <= at and (not receivers[a] or sender in receivers[a]):
                unheard.setdefault(a, set()).add(sender)


def _integer_times(times: pd.Series) -> np.ndarray:
    """Times as integers of their own unit (missing ones as the smallest), comparable as the
    times are, without a Python object per time."""
    values = pd.to_datetime(times, utc=True).array.as_unit("ns")
    return np.asarray(values.asi8, dtype=np.int64)


def _receiver_set(receiver) -> frozenset:
    """The robots a message went to (a joined list splits; ``unknown`` is none)."""
    if not isinstance(receiver, str) or receiver == UNKNOWN:
        return frozenset()
    return frozenset(receiver.split(", "))


def _what_followed(lost: pd.DataFrame, instances: pd.DataFrame, following: int) -> list[str]:
    """The sender's next activities (started after the message was first sent); none when the
    log does not say which robot did what."""
    if ROBOT not in instances.columns:
        return [""] * len(lost)
    mine = instances.rename(columns={ROBOT: "sender"})
    return what_followed(mine, lost, [CASE, "sender"], "sent_at", following)["then"].tolist()


def _lost_effect(effect: pd.DataFrame) -> dict:
    if effect.empty or effect["cases_without"].iloc[0] == 0:
        return {}
    row = effect.iloc[0]
    return {
        "lost_cases_longer_by": float(row["extra_mean"]),
        "lost_cases_p_value": None if pd.isna(row["p_value"]) else float(row["p_value"]),
    }


def _type_of(activity: str) -> str:
    return activity[:-1] + "!" if activity.endswith("?") else activity


def _first(events: pd.DataFrame, keys: list[str], column: str) -> pd.Series:
    if column not in events.columns:
        return pd.Series(dtype=object)
    # events usually come in time order already; a stable sort would leave them as they are
    in_order = events[TIMESTAMP].is_monotonic_increasing
    ordered = events if in_order else events.sort_values(TIMESTAMP, kind="stable")
    return ordered.groupby(keys)[column].first().astype(object)


def _distinct(events: pd.DataFrame, keys: list[str], column: str) -> pd.Series:
    if column not in events.columns:
        return events.groupby(keys).size().clip(upper=1)
    return events.groupby(keys)[column].nunique()


def _joined(deliveries: pd.DataFrame, keys: list[str], column: str) -> pd.Series:
    """Per message, its distinct ``column`` values in text order, joined (most messages have
    one)."""
    grouped = deliveries.groupby(keys, sort=True)
    message = grouped.ngroup().to_numpy()
    codes, names = pd.factorize(deliveries[column].astype(str))
    names = names.to_numpy(object)
    rank = np.empty(len(names), dtype=np.int64)
    rank[np.argsort(names, kind="stable")] = np.arange(len(names))
    # each (message, value) once, messages in key order and values in text order within one
    pairs = sorted_distinct(message[message >= 0] * len(names) + rank[codes[message >= 0]])
    labels = np.sort(names)[pairs % len(names)] + ", "
    joined = pd.Series(labels, dtype=object).groupby(pairs // len(names)).sum()
    return pd.Series(joined.str.slice(stop=-2).to_numpy(object), index=grouped.size().index)


def _lookup(frame: pd.DataFrame, keys: list[str], values: pd.Series) -> pd.Series:
    index = pd.MultiIndex.from_frame(frame[keys]) if len(keys) > 1 else frame[keys[0]]
    return pd.Series(values.reindex(index).to_numpy(), index=frame.index)


def _in(frame: pd.DataFrame, other: pd.DataFrame, keys: list[str]) -> np.ndarray:
    if len(keys) == 1:
        return frame[keys[0]].isin(other[keys[0]]).to_numpy()
    return pd.MultiIndex.from_frame(frame[keys]).isin(pd.MultiIndex.from_frame(other[keys]))


def _involving(log: pd.DataFrame, messages: pd.DataFrame, robot: str) -> pd.Series:
    """Which messages ``robot`` sent or received."""
    if ROBOT not in log.columns:
        return pd.Series(False, index=messages.index)
    keys = _keys(messages)
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


def _latency_figures(grouped) -> pd.DataFrame:
    latency = grouped["latency"]
    table = latency.agg(latency_mean="mean", latency_median="median")
    table["latency_p95"] = latency.quantile(0.95)  # one pass, not a call per channel
    table["latency_max"] = latency.max()
    return table


def _by_type(messages: pd.DataFrame, deliveries: pd.DataFrame) -> pd.DataFrame:
    grouped = messages.groupby(TYPE, sort=True)
    table = grouped.agg(
        sent=("sent", "sum"),
        received=("received", "sum"),
        lost=("lost", "sum"),
        unobserved=("unobserved", "sum"),
        delayed=("delayed", "sum"),
        resends=("resends", "sum"),
        resends_same_id=("resends_same_id", "sum"),
        resends_new_id=("resends_new_id", "sum"),
        recovered=("recovered", "sum"),
        receivers_mean=("receivers", "mean"),
    )
    table = table.join(_latency_figures(grouped))
    table["receive_tagged"] = table["received"] > 0
    # a loss rate only where losses can be seen: a type without receive tags has none
    table["loss_rate"] = table["lost"] / table["sent"].where(
        (table["sent"] > 0) & table["receive_tagged"]
    )
    # the distinct sender -> receiver pairs of each type, counted at once (no call per type)
    pairs = deliveries[[TYPE, "sender", "receiver"]].drop_duplicates()
    table["channels"] = pairs.groupby(TYPE).size()
    return table.reset_index()


def _by_channel(deliveries: pd.DataFrame) -> pd.DataFrame:
    grouped = deliveries.groupby(CHANNEL, sort=True, dropna=False)
    table = grouped.agg(
        sent=("sent_at", "count"),
        received=("received", "sum"),
        lost=("lost", "sum"),
        unobserved=("unobserved", "sum"),
        delayed=("delayed", "sum"),
    )
    return table.join(_latency_figures(grouped)).reset_index()


def _summary(messages: pd.DataFrame, channels: pd.DataFrame, lost_effect: dict) -> dict:
    totals = {
        column: int(messages[column].sum())
        for column in (
            "sent",
            "received",
            "lost",
            "unobserved",
            "delayed",
            "resends",
            "resends_same_id",
            "resends_new_id",
            "recovered",
        )
    }
    pairs = channels[["sender", "receiver"]].drop_duplicates()
    return {
        "messages": len(messages),
        **totals,
        "untagged_types": untagged_types(messages),
        "channels": len(pairs),
        **lost_effect,
    }


def _figure(types: pd.DataFrame):
    from plotly.subplots import make_subplots  # 0.25 s to import: only a figure needs it

    figure = make_subplots(
        rows=1, cols=2, subplot_titles=("Messages", "Latency, first send to first receive (s)")
    )
    for column, colour in (
        ("received", "#2ca02c"),
        ("lost", "#d62728"),
        ("unobserved", "#bbbbbb"),
        ("resends", "#ff7f0e"),
        ("delayed", "#8c564b"),
    ):
        figure.add_bar(
            x=types[TYPE], y=types[column], name=column, marker_color=colour, row=1, col=1
        )
    for column, colour in (("latency_mean", "#1f77b4"), ("latency_p95", "#9467bd")):
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
