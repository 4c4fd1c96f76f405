"""How one event log is read: which column plays which role, and what became of every row.

Logs come from many tools, each with its own conventions. This module is the one place that
decides how a log is read, and :class:`Reading` reports the decisions so a user can check them
(``robotale inspect LOG``) before trusting a single figure. The rules (docs/reading.md):

- **Columns** are recognised by their usual names (:data:`SYNONYMS`) unless ``--map`` names
  them. ``org:resource`` is the robot when it is the only robot column; next to an
  instance-like column (``robot``, ``robot_id``, ``resource`` ...) it is the robot's type.
- **Missing**: the markers of :data:`MISSING_MARKERS` mean "no value" in every column; they are
  counted per column.
- **Lifecycle**: a row whose lifecycle is start or complete (or a synonym such as ``begin``,
  ``end``) is a control-flow event, whatever its state says. Only a row whose lifecycle is
  ``none`` or missing and whose state says in-progress is a sample (continuous data between a
  start and its completion). Other rows without a lifecycle are completions (pm4py's default);
  ``none`` alone is an instant event. A row with any other lifecycle (``schedule``,
  ``suspend`` ...) is dropped, counted and named.
- **Cases**: the case column, else the XES trace, else one case, or with a case gap a new case
  after every pause of at least that long.
- **Copies**: a row equal to an earlier row in every cell is dropped, counted and named (an
  event logged twice would otherwise be a second activity, a resend or a loop).
"""

from __future__ import annotations

import contextlib
import csv
import re
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import pandas as pd
import pyarrow as pa
import pyarrow.csv as pa_csv

from robotale.errors import InputError
from robotale.eventlog import schema

#: canonical column -> names it is recognised by (compared ignoring case, blanks, "_" and "-"),
#: best first. ``org:resource`` comes last for the robot, so an instance-like column wins and
#: ``org:resource`` is then read as the robot type.
SYNONYMS: dict[str, tuple[str, ...]] = {
    schema.CASE: ("case", "case:concept:name", "case_id", "trace", "trace_id"),
    schema.ACTIVITY: ("activity", "concept:name", "activity_name", "task"),
    schema.TIMESTAMP: ("time", "timestamp", "time:timestamp", "datetime"),
    schema.LIFECYCLE: ("lifecycle", "lifecycle:transition", "transition"),
    schema.STATE: ("state", "lifecycle:state"),
    schema.ROBOT: ("robot", "robot_id", "robot_name", "resource", "agent", "org:resource"),
    schema.ROBOT_TYPE: ("robot_type", "org:role", "org:resource"),
    schema.MSG_ID: ("msg_id", "message_id"),
    schema.MSG_ROLE: ("msg_role", "message_role"),
    schema.MSG_PAYLOAD: ("msg_payload", "payload", "message_payload"),
    schema.MSG_SENDER: ("msg_sender", "message_sender", "sender"),
    schema.MSG_RECEIVER: ("msg_receiver", "message_receiver", "receiver"),
    schema.EVENT_ID: ("event_id", "id"),
    schema.EXECUTION_ID: ("execution_id", "concept:instance", "activity_instance"),
    schema.X: ("x",),
    schema.Y: ("y",),
    schema.Z: ("z",),
    schema.BATTERY: ("battery",),
}
#: columns whose values are names, never numbers ("38" stays the case "38").
TEXT_COLUMNS = (
    schema.CASE,
    schema.ACTIVITY,
    schema.LIFECYCLE,
    schema.STATE,
    schema.ROBOT,
    schema.ROBOT_TYPE,
    schema.MSG_ID,
    schema.MSG_ROLE,
    schema.MSG_PAYLOAD,
    schema.MSG_SENDER,
    schema.MSG_RECEIVER,
    schema.EVENT_ID,
    schema.EXECUTION_ID,
)
#: cell values that mean "no value" in every column (compared after stripping blanks). Case
#: matters: the lowercase lifecycle ``none`` is an instant event, not a missing value.
MISSING_MARKERS = frozenset({"", "null", "NULL", "None", "NaN", "nan", "-", "N/A", "n/a"})
#: lifecycle values (lowercased) and what they mean.
LIFECYCLE_VALUES: dict[str, str] = {
    "start": schema.START,
    "begin": schema.START,
    "started": schema.START,
    "complete": schema.COMPLETE,
    "completed": schema.COMPLETE,
    "end": schema.COMPLETE,
    "ended": schema.COMPLETE,
    "done": schema.COMPLETE,
    "finish": schema.COMPLETE,
    "finished": schema.COMPLETE,
    "none": schema.NONE,
    "instant": schema.NONE,
    # an end that says how it went (ROS 2 action goals, XES' abort transitions): robots fail,
    # and the outcome stays in the log
    "aborted": schema.ABORTED,
    "abort": schema.ABORTED,
    "ate_abort": schema.ABORTED,
    "pi_abort": schema.ABORTED,
    "cancelled": schema.CANCELLED,
    "canceled": schema.CANCELLED,
    "withdraw": schema.CANCELLED,
}
#: a state says in-progress when, lowercased without blanks, "_" and "-", it is this.
INPROGRESS_STATE = "inprogress"
#: what a source column is for, in words, by its canonical name.
ROLE_NAMES: dict[str, str] = {
    schema.CASE: "case",
    schema.ACTIVITY: "activity",
    schema.TIMESTAMP: "time",
    schema.LIFECYCLE: "lifecycle",
    schema.STATE: "state",
    schema.ROBOT: "robot",
    schema.ROBOT_TYPE: "robot type",
    schema.MSG_ID: "message id",
    schema.MSG_ROLE: "message role",
    schema.MSG_PAYLOAD: "message payload",
    schema.MSG_SENDER: "message sender",
    schema.MSG_RECEIVER: "message receiver",
    schema.EVENT_ID: "event id",
    schema.EXECUTION_ID: "pairing key",
    schema.X: "perspective (x)",
    schema.Y: "perspective (y)",
    schema.Z: "perspective (z)",
    schema.BATTERY: "perspective (battery)",
}
#: event kinds of :func:`event_kinds`, in the order a reading lists them.
KINDS = ("start", "complete", "instant", "sample")
#: ends of an activity that failed or was called off: completions that keep their outcome
OUTCOMES = (schema.ABORTED, schema.CANCELLED)
#: why a row that repeats an earlier one cell for cell is dropped
COPY_REASON = "an exact copy of an earlier row (the event counts once)"
#: a dropped row's lines are listed up to this many.
SHOWN_LINES = 5
#: the pause offered as the end of a session when a log without cases spans several days
SESSION_GAP = "1h"


@dataclass
class Reading:
    """How a log was read: returned next to the DataFrame (see ``read_log_with_reading``)."""

    source: str
    #: source column -> its role in words ("robot", "robot type", "perspective" ...)
    columns: dict[str, str]
    #: how cases are told apart, in words
    case: str
    cases: int
    #: robot instance -> its type (None where the log gives none)
    robots: dict[str, str | None]
    #: events by kind: start, complete, instant, sample
    events: dict[str, int]
    #: how a start finds its completion, in words
    pairing: str
    rows: int
    #: source column -> cells read as missing
    missing: dict[str, int] = field(default_factory=dict)
    #: reason -> the file lines of the rows dropped for it
    dropped: dict[str, list[int]] = field(default_factory=dict)
    #: decisions worth knowing that are not problems
    notes: list[str] = field(default_factory=list)
    warnings: list[str] = field(default_factory=list)
    #: the case gap offered for a log without a case column that spans several days (its runs
    #: are then sessions apart, and one case would count the nights as waiting); else None
    session_gap: str | None = None

    @property
    def kept(self) -> int:
        return self.rows - sum(len(lines) for lines in self.dropped.values())

    @property
    def lifecycle(self) -> str:
        """The lifecycle model in words."""
        parts = []
        if self.events["start"] and self.events["complete"]:
            parts.append("start/complete pairs")
        elif self.events["complete"] or self.events["instant"]:
            parts.append("instant events")
        if self.events["sample"]:
            parts.append("in-progress samples")
        return " with ".join(parts) or "no control-flow events"


# -- columns -----------------------------------------------------------------------------------


def column_mapping(
    path: Path, columns: list[str], explicit: Mapping[str, str] | None = None
) -> dict[str, str]:
    """Source column -> canonical column, explicit entries first, then :data:`SYNONYMS`."""
    explicit = dict(explicit or {})
    for source in explicit:
        if source not in columns:
            raise InputError(
                f"{path} has no column {source!r} to map; its columns are {listing(columns)}."
            )
    renames = {source: canonical_name(target) for source, target in explicit.items()}
    taken = set(renames.values())
    for canonical, names in SYNONYMS.items():
        if canonical in taken:
            continue
        wanted = [normalised(name) for name in names]
        found = [c for c in columns if c not in renames and normalised(c) in wanted]
        if found:
            renames[min(found, key=lambda c: wanted.index(normalised(c)))] = canonical
            taken.add(canonical)
    return renames


def column_roles(
    columns: list[str], renames: Mapping[str, str], case: str | None
) -> dict[str, str]:
    """Every source column's role in words; unrecognised columns are perspectives."""
    roles = {}
    for column in columns:
        canonical = renames.get(column, column)
        roles[column] = ROLE_NAMES.get(canonical, "perspective")
    if case is not None:
        roles[case] = "case"
    return roles


def canonical_name(target: str) -> str:
    """``time`` -> ``time:timestamp`` etc.; any other target is kept as the new name."""
    short_to_long = {short: long for long, short in schema.CSV_NAMES.items()}
    return short_to_long.get(target, target)


def normalised(name: str) -> str:
    return re.sub(r"[\s_\-]", "", str(name)).lower()


def listing(columns: list[str]) -> str:
    return ", ".join(repr(c) for c in columns[:20]) + (" ..." if len(columns) > 20 else "")


# -- missing values ----------------------------------------------------------------------------


_MARKER = "|".join(re.escape(m) for m in sorted(MISSING_MARKERS, key=len, reverse=True) if m)
#: a CSV cell holding a marker or nothing, with blanks around it
_PADDED = re.compile(rf"(?:^|,)(?:[ \t]+(?:{_MARKER})?[ \t]*|(?:{_MARKER})[ \t]+)(?=,|\r?$)", re.M)


def has_padded_markers(text: str) -> bool:
    """Whether a CSV text may hold a marker (or nothing) with blanks around it, which only
    :func:`mark_missing` recognises; one regular expression over the text, so files without
    any (nearly all) are read at the speed of pandas' own parser."""
    # a blank next to a delimiter or a line's end is rare: looked for in one pass over the
    # bytes (a character of more than one byte has none of these in it)
    edges = text[:1] + text.rstrip("\r\n")[-1:]
    if not _blank_beside_an_edge(text) and not edges.isspace():
        return False
    return _PADDED.search(text) is not None


def _blank_beside_an_edge(text: str) -> bool:
    """Whether a blank (space or tab) follows a comma or a line break, or comes before a
    comma or a line's end, anywhere in ``text``."""
    data = np.frombuffer(text.encode("utf-8", "surrogatepass"), dtype=np.uint8)
    blanks = np.flatnonzero((data == ord(" ")) | (data == ord("\t")))
    before = data[blanks[blanks > 0] - 1]
    after = data[blanks[blanks < len(data) - 1] + 1]
    return bool(
        np.isin(before, [ord(","), ord("\n")]).any()
        or np.isin(after, [ord(","), ord("\n"), ord("\r")]).any()
    )


def mark_missing(table: pd.DataFrame) -> dict[str, int]:
    """Replace the :data:`MISSING_MARKERS` of every text cell by NaN, in place; the count of
    cells replaced per column (columns without any are left out)."""
    counts = {}
    for column in table.columns:
        values = table[column]
        if not (pd.api.types.is_object_dtype(values) or pd.api.types.is_string_dtype(values)):
            continue
        # numbers and booleans (XES) never print as a marker, so all cells can go as text
        marked = values.astype("string").str.strip().isin(MISSING_MARKERS)
        marked = marked.fillna(False).astype(bool)
        if marked.any():
            table[column] = values.mask(marked)
            counts[str(column)] = int(marked.sum())
    return counts


def typed_columns(table: pd.DataFrame, text: list[str]) -> pd.DataFrame:
    """Columns read as text made numbers where every value is one (``text`` columns stay)."""
    for column in table.columns:
        if column in text:
            continue
        with contextlib.suppress(ValueError, TypeError):  # names or mixed values stay text
            numbers = pd.to_numeric(table[column])
            if not _beyond_int64(numbers):
                table[column] = numbers
    return table


#: the integers Neo4j (and numpy) can hold; a longer run of digits is an id, kept as text
_INT64 = (-(2**63), 2**63 - 1)


def huge_integer_columns(table: pd.DataFrame) -> list[str]:
    """The columns pandas read as integers too large for 64 bits (a serial number, a hash in
    digits): they cannot be stored as numbers, so they are read again as text."""
    return [str(column) for column in table.columns if _beyond_int64(table[column])]


def _beyond_int64(column: pd.Series) -> bool:
    if column.dtype != object:
        return False
    return any(
        isinstance(value, int)
        and not isinstance(value, bool)
        and not _INT64[0] <= value <= _INT64[1]
        for value in column
    )


# -- lifecycle ---------------------------------------------------------------------------------


def event_kinds(log: pd.DataFrame) -> pd.Series:
    """Each row's kind: start, complete, instant, sample, or ``?<value>`` for a lifecycle value
    that is none of these (such rows are dropped)."""
    in_progress = _in_progress(log)
    if schema.LIFECYCLE not in log.columns:
        kinds = np.where(in_progress, "sample", "complete").astype(object)
        return pd.Series(kinds, index=log.index, dtype=object)
    # each distinct lifecycle value read once (a log repeats a handful), its rows by code;
    # a missing value is the last code
    codes, values = pd.factorize(log[schema.LIFECYCLE].astype("string"))
    raw = pd.Series(values, dtype="string").str.strip()
    meaning = raw.str.lower().map(LIFECYCLE_VALUES).to_numpy(object)
    kind_of = np.array([*map(_kind, raw.to_numpy(object), meaning), "complete"], dtype=object)
    # no transition (missing, or none) and a state in progress: a sample
    silent = np.append(meaning == schema.NONE, True)[codes]
    kinds = kind_of[codes]
    kinds[silent & in_progress] = "sample"
    return pd.Series(kinds, index=log.index, dtype=object)


def _kind(raw: object, meaning: object) -> str:
    """The kind of a row whose lifecycle value is ``raw`` (stripped), meaning ``meaning``."""
    if pd.isna(raw):  # no lifecycle: a recorded completion, as pm4py reads it
        return "complete"
    if meaning in (schema.START, schema.COMPLETE, *OUTCOMES):
        return str(meaning)
    if meaning == schema.NONE:
        return "instant"
    return f"?{raw}"


def understood(kinds: pd.Series) -> pd.Series:
    """Which rows :func:`event_kinds` could read (the others are dropped)."""
    return kinds.isin(KINDS + OUTCOMES)


def _in_progress(log: pd.DataFrame) -> pd.Series:
    if schema.STATE not in log.columns:
        return pd.Series(False, index=log.index).to_numpy(bool)
    # each distinct state normalised once: a log repeats a handful of them
    codes, states = pd.factorize(log[schema.STATE].astype("string"))
    meant = np.array([normalised(state) == INPROGRESS_STATE for state in states], dtype=bool)
    return np.append(meant, False)[codes]


def lifecycle_columns(log: pd.DataFrame, kinds: pd.Series) -> list[str]:
    """Set the canonical lifecycle (and state, where the log has one) from each row's kind;
    notes on rows whose state the lifecycle overruled."""
    notes = []
    if schema.STATE in log.columns:
        overruled = kinds.isin(["start", "complete"]).to_numpy(bool) & _in_progress(log)
        if overruled.any():
            counts = kinds[overruled].value_counts()
            said = " and ".join(f"{counts[k]:,} {k}" for k in ("start", "complete") if k in counts)
            notes.append(
                f"{said} rows say the state is in progress: read as control-flow events "
                "(the lifecycle wins over the state)."
            )
        samples = (kinds == "sample").to_numpy(bool)
        log[schema.STATE] = pd.Series(schema.NONE, index=log.index, dtype="string")
        log.loc[samples, schema.STATE] = schema.INPROGRESS
    transitions = {"start": schema.START, "complete": schema.COMPLETE}
    transitions |= {outcome: outcome for outcome in OUTCOMES}
    # a handful of kinds: each turned into its lifecycle once, the rows by code
    codes, found = pd.factorize(kinds)
    lifecycle = np.array([transitions.get(kind, schema.NONE) for kind in found], dtype=object)
    log[schema.LIFECYCLE] = pd.Series(lifecycle[codes], index=log.index, dtype="string")
    return notes


def dropped_rows(kinds: pd.Series, lines: pd.Series) -> dict[str, list[int]]:
    """Reason -> file lines of the rows whose lifecycle is not understood."""
    unknown = kinds[~understood(kinds)]
    return {
        f"lifecycle {value[1:]!r} is not a start, an end or none": lines[group.index].tolist()
        for value, group in unknown.groupby(unknown, sort=True)
    }


def exact_copies(
    table: pd.DataFrame, lines: pd.Series, events: np.ndarray, identified: str | None = None
) -> tuple[np.ndarray, dict[str, list[int]]]:
    """Which of the rows that are ``events`` are copies of an event row (a logger that wrote
    an event twice), and their file lines under the reason they are dropped: an event counts
    once, never as a second activity, message or loop.

    In a log whose rows carry event ids (``identified``) a row equal to any earlier one is a
    copy: the id says it is the same event. Otherwise only the row just before counts: a log
    on a simulated clock repeats a whole row legitimately (the same activity started again at
    the same instant after others), so a row equal to one further back is a second event."""
    if identified:
        # a copy repeats its id: only rows whose id comes again are compared cell by cell
        again = table[identified].duplicated(keep=False).to_numpy(bool)
        copies = np.zeros(len(table), dtype=bool)
        copies[again] = table[again].duplicated(keep="first").to_numpy(bool)
        copies &= events
        return copies, ({COPY_REASON: lines[copies].tolist()} if copies.any() else {})
    rows = table[events]
    before = rows.shift()
    same = (rows.eq(before) | (rows.isna() & before.isna())).all(axis=1).to_numpy(bool, copy=True)
    if len(same):
        same[0] = False  # the first event has no row before it
    copies = np.zeros(len(table), dtype=bool)
    copies[np.flatnonzero(events)] = same
    if not copies.any():
        return copies, {}
    return copies, {COPY_REASON: lines[copies].tolist()}


def pairing_description(log: pd.DataFrame, renames: Mapping[str, str]) -> str:
    """How a start finds its completion (the keys robotale's activity instances use)."""
    keys = [
        name
        for column, name in ((schema.CASE, "case"), (schema.ROBOT, "robot"))
        if column in log.columns
    ]
    within = ", ".join([*keys, "activity"])
    source = {canonical: column for column, canonical in renames.items()}
    if schema.EXECUTION_ID in log.columns:
        return f"by {source.get(schema.EXECUTION_ID, schema.EXECUTION_ID)} within {within}"
    if schema.MSG_ID in log.columns:
        key = source.get(schema.MSG_ID, schema.MSG_ID)
        return f"by {key} within {within} (first in, first out where there is none)"
    return f"first in, first out within {within}"


# -- messages ----------------------------------------------------------------------------------


def message_roles_from_ends(log: pd.DataFrame) -> list[str]:
    """Where a message event has no role, its robot being the message's sender or receiver
    tells; notes on how many roles were so derived."""
    ends = (schema.MSG_ID, schema.ROBOT, schema.MSG_SENDER, schema.MSG_RECEIVER)
    if not all(column in log.columns for column in ends):
        return []
    if schema.MSG_ROLE not in log.columns:
        log[schema.MSG_ROLE] = pd.Series(pd.NA, index=log.index, dtype="string")
    open_role = log[schema.MSG_ROLE].isna() & log[schema.MSG_ID].notna()
    robot = log[schema.ROBOT].astype("string")
    derived = 0
    for role, column in ((schema.SEND, schema.MSG_SENDER), (schema.RECEIVE, schema.MSG_RECEIVER)):
        match = (open_role & (robot == log[column].astype("string"))).fillna(False).astype(bool)
        log.loc[match, schema.MSG_ROLE] = role
        open_role &= ~match
        derived += int(match.sum())
    if not derived:
        return []
    return [f"{derived:,} message events take their role from msg_sender / msg_receiver."]


# -- cases -------------------------------------------------------------------------------------


_DURATION = re.compile(r"^\s*(\d+(?:\.\d+)?)\s*(ms|s|sec|min|m|h|d)\s*$", re.IGNORECASE)
_UNITS = {"ms": "ms", "s": "s", "sec": "s", "min": "min", "m": "min", "h": "h", "d": "D"}


def parse_duration(text: str | pd.Timedelta) -> pd.Timedelta:
    """``1h``, ``90s``, ``30min``, ``2d``, ``500ms`` as a positive duration."""
    if isinstance(text, pd.Timedelta):
        duration = text
    else:
        match = _DURATION.match(str(text))
        if not match:
            raise InputError(f"--case-gap {text!r} is not a duration such as 1h, 90s, 30min or 2d.")
        duration = pd.Timedelta(float(match.group(1)), unit=_UNITS[match.group(2).lower()])
    if duration <= pd.Timedelta(0):
        raise InputError(f"--case-gap {text!r} must be longer than nothing.")
    return duration


def duration_text(duration: pd.Timedelta) -> str:
    """``1h``, ``90s``, ``30min``: the largest unit that says the duration exactly."""
    seconds = duration.total_seconds()
    for unit, size in (("d", 86400), ("h", 3600), ("min", 60), ("s", 1)):
        if seconds >= size and seconds % size == 0:
            return f"{int(seconds // size)}{unit}"
    return f"{seconds:g}s"


def cases_by_gap(times: pd.Series, gap: pd.Timedelta) -> pd.Series:
    """Case ids ``"1"``, ``"2"`` ...: a new case after every pause of at least ``gap`` between
    consecutive events of the whole log (in time order; ties keep the file's order)."""
    ordered = times.sort_values(kind="stable")
    number = (ordered.diff() >= gap).cumsum() + 1
    return number.astype(str).astype("string").reindex(times.index)


def days_spanned(times: pd.Series) -> list[str]:
    """The calendar days (in the log's own offset) its events fall on."""
    days = times.dt.normalize().drop_duplicates()  # in the log's own offset
    return sorted(day.strftime("%Y-%m-%d") for day in days)


# -- what the reading finds --------------------------------------------------------------------


def robot_types(log: pd.DataFrame) -> tuple[dict[str, str | None], list[str]]:
    """Robot instance -> its type; warnings for robots with more than one type."""
    if schema.ROBOT not in log.columns:
        return {}, []
    robots = log[schema.ROBOT].dropna().astype(str)
    if schema.ROBOT_TYPE not in log.columns:
        return dict.fromkeys(sorted(robots.unique())), []
    types = log.loc[robots.index, schema.ROBOT_TYPE].astype("string")
    pairs = pd.DataFrame({"robot": robots, "type": types}).dropna().drop_duplicates()
    found: dict[str, str | None] = dict.fromkeys(sorted(robots.unique()))
    warnings = []
    for robot, group in pairs.groupby("robot", sort=True):
        found[str(robot)] = str(group["type"].iloc[0])
        if len(group) > 1:
            names = ", ".join(sorted(group["type"]))
            warnings.append(f"The robot {robot!r} has {len(group)} types ({names}).")
    return found, warnings


#: canonical columns that name entities: one value over the whole log tells nothing apart
#: (robot types, senders and receivers may well have one: a team of one kind, one sender).
ENTITY_COLUMNS = (schema.CASE, schema.ROBOT, schema.EXECUTION_ID, schema.MSG_ID)


def single_value_warnings(log: pd.DataFrame, renames: Mapping[str, str]) -> list[str]:
    """A column that looks like an entity (a robot, a case, an id ...) but has one value."""
    source = {canonical: column for column, canonical in renames.items()}
    candidates = [c for c in ENTITY_COLUMNS if c in source]
    candidates += [c for c in log.columns if c not in schema.CSV_NAMES and _looks_like_id(c)]
    warnings = []
    for column in candidates:
        values = log[column].dropna().unique()
        if len(values) == 1 and log[column].notna().sum() > 1:
            name = source.get(column, column)
            warnings.append(
                f"The column {name!r} ({ROLE_NAMES.get(column, 'an id')}) has one value, "
                f"{str(values[0])!r}, on every row that has one: it tells nothing apart."
            )
    return warnings


def _looks_like_id(column: str) -> bool:
    name = normalised(column)
    return name.endswith("id") and len(name) > 2 and not name.startswith("case:")


def paired_seconds(log: pd.DataFrame) -> pd.Series:
    """The seconds from each start to the completion it pairs with: within the same case,
    robot, activity and pairing key, the n-th start with the n-th completion (a rough pairing,
    enough to tell whether any activity lasts at all)."""
    keys = [c for c in (schema.CASE, schema.ROBOT, schema.ACTIVITY) if c in log.columns]
    if schema.EXECUTION_ID in log.columns:
        keys.append(schema.EXECUTION_ID)
    # one integer per group, so the pairs are matched on numbers, not on names
    group = np.zeros(len(log), dtype=np.int64)
    for key in keys:
        codes, uniques = pd.factorize(log[key], use_na_sentinel=False)
        group, _ = pd.factorize(group * (len(uniques) + 1) + codes)
    lifecycle = log[schema.LIFECYCLE]
    ends = []
    for kind in (schema.START, schema.COMPLETE):
        chosen = (lifecycle == kind).fillna(False).to_numpy(bool)
        rows = pd.DataFrame({"_g": group[chosen], "_t": log[schema.TIMESTAMP].array[chosen]})
        ends.append(rows.assign(_n=rows.groupby("_g", sort=False).cumcount()))
    pairs = ends[0].merge(ends[1], on=["_g", "_n"], suffixes=("_start", "_end"))
    return (pairs["_t_end"] - pairs["_t_start"]).dt.total_seconds()


def no_pairs_warning(log: pd.DataFrame) -> list[str]:
    seconds = paired_seconds(log)
    if seconds.empty:
        return [
            "No start/complete pairs found: every activity lasts 0 s (map the column that says "
            "start and complete with --map COLUMN=lifecycle if there is one)."
        ]
    if (seconds == 0).all():
        return [
            f"Every one of the {len(seconds):,} start/complete pairs has one time for both: "
            "every activity lasts 0 s (are the starts stamped with the completion's time?)."
        ]
    return []


def days_warning(path: Path, log: pd.DataFrame) -> list[str]:
    days = days_spanned(log[schema.TIMESTAMP])
    if len(days) < 2:
        return []
    return [
        f"{path.name} has no case column and spans {len(days)} days ({days[0]} to {days[-1]}), "
        f"so it is read as one case: --case-gap {SESSION_GAP} starts a new case after every "
        "pause of an hour or more (or name the column that tells runs apart)."
    ]


def dropped_note(dropped: Mapping[str, list[int]]) -> list[str]:
    lines = []
    for reason, where in dropped.items():
        shown = ", ".join(str(line) for line in where[:SHOWN_LINES])
        more = " ..." if len(where) > SHOWN_LINES else ""
        lines.append(f"{len(where):,} dropped: {reason} (line {shown}{more})")
    return lines


# -- as text -----------------------------------------------------------------------------------


def format_reading(reading: Reading, *, short: bool = False) -> str:
    """The reading as plain lines: all of it, or (``short``) what a command shows before it
    works on the log: events kept and dropped, cases, robots, notes and warnings."""
    lines = [
        f"Read {reading.source}: {reading.kept:,} of {reading.rows:,} rows kept, "
        f"{reading.cases:,} case{'s' if reading.cases != 1 else ''} ({reading.case}), "
        f"{len(reading.robots):,} robot{'s' if len(reading.robots) != 1 else ''}, "
        f"{reading.lifecycle}."
    ]
    if not short:
        lines += _details(reading)
    lines += [f"  {line}" for line in dropped_note(reading.dropped)]
    lines += [f"  note: {note}" for note in reading.notes]
    lines += [f"  warning: {warning}" for warning in reading.warnings]
    return "\n".join(lines)


def marker_listing() -> str:
    """The markers read as no value, in words: 'empty cells and null, NULL, None ...'."""
    shown = sorted((m for m in MISSING_MARKERS if m), key=lambda m: (m.lower(), m))
    return "empty cells and " + ", ".join(shown)


def _details(reading: Reading) -> list[str]:
    width = max((len(column) for column in reading.columns), default=0)
    columns = [f"    {column:<{width}} -> {role}" for column, role in reading.columns.items()]
    robots = ", ".join(
        robot if kind is None else f"{robot} ({kind})" for robot, kind in reading.robots.items()
    )
    shown = [*KINDS, *(kind for kind in OUTCOMES if reading.events.get(kind))]
    events = ", ".join(f"{reading.events[kind]:,} {kind}" for kind in shown)
    missing = ", ".join(f"{column} {count:,}" for column, count in reading.missing.items())
    return [
        "  columns:",
        *columns,
        f"  cases:     {reading.cases:,} ({reading.case})",
        f"  robots:    {robots or '-'}",
        f"  events:    {events}",
        f"  lifecycle: {reading.lifecycle}; pairs {reading.pairing}",
        f"  missing:   {missing or '-'}",
        f"  no value:  {marker_listing()}",
        f"  rows:      {reading.rows:,} read, {reading.kept:,} kept, "
        f"{reading.rows - reading.kept:,} dropped",
    ]


# -- the fast parse ----------------------------------------------------------------------------


#: the column types pyarrow's reader infers that are also what pandas' parser would give;
#: any other (dates, times, booleans) sends the file to pandas' parser
_SAME_AS_PANDAS = (pa.types.is_string, pa.types.is_int64, pa.types.is_float64, pa.types.is_null)
#: beyond this a float's integer part is no longer exact: a column holding such a value may
#: be integers pandas keeps whole (or as text), not floats
_EXACT_FLOAT = 2**53


def arrow_csv(text: str, text_columns: list[str], times: str | None) -> pd.DataFrame | None:
    """The CSV's cells as pandas' parser reads them (markers as whole cells missing, the
    ``text_columns`` as text, other columns numbers where every value is one, the ``times``
    column as text unless it holds numbers), read by
    pyarrow's multi-threaded reader in a third of the time; ``None`` where the file may read
    otherwise in pandas (a blank beside a cell, a row of another width, a value pyarrow
    reads as a date, a time, a truth value or a huge number, a column of text pandas would
    read as numbers), which the caller then reads with pandas' parser, whose error
    sentences it keeps."""
    if _blank_beside_an_edge(text):  # pandas trims blanks around numbers, pyarrow does not
        return None
    header = next(csv.reader([text.partition("\n")[0]]), [])
    try:
        table = pa_csv.read_csv(
            pa.BufferReader(text.encode("utf-8", "surrogatepass")),
            parse_options=pa_csv.ParseOptions(newlines_in_values=False),
            convert_options=pa_csv.ConvertOptions(
                column_types=dict.fromkeys(
                    (c for c in [*text_columns, times] if c in header), pa.string()
                ),
                null_values=sorted(MISSING_MARKERS),
                strings_can_be_null=True,
                quoted_strings_can_be_null=True,
            ),
        )
    except (pa.ArrowException, ValueError):
        return None
    if table.column_names != header:
        return None
    frame = table.to_pandas()
    for name, kind in zip(table.column_names, table.schema.types, strict=True):
        if _read_otherwise(kind, frame[name], text=name in text_columns):
            return None
        if pa.types.is_null(kind):  # nothing but missing cells: pandas' NaN column
            frame[name] = np.nan
    return frame


def _read_otherwise(kind: pa.DataType, values: pd.Series, *, text: bool) -> bool:
    """Whether pandas' parser may read a column pyarrow read as ``kind`` otherwise."""
    if not any(same(kind) for same in _SAME_AS_PANDAS):
        return True
    if pa.types.is_float64(kind):
        return _holds_huge_integers(values)
    return pa.types.is_string(kind) and not text and _numbers(values)


def _holds_huge_integers(values: pd.Series) -> bool:
    numbers = values.to_numpy(float)
    whole = np.isfinite(numbers) & (np.abs(numbers) >= _EXACT_FLOAT)
    return bool((whole & (numbers == np.floor(numbers))).any())


def _numbers(values: pd.Series) -> bool:
    """Whether every value of a text column reads as a number (pandas' parser would have
    made it one)."""
    present = values.dropna()
    try:
        if len(present):  # most text fails at its first value: tried alone, before them all
            float(present.iloc[0])
        pd.to_numeric(present)
    except (ValueError, TypeError):
        return False
    return True
