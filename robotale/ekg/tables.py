"""The EKG of an event log as tables, computed in pandas before anything is written.

Everything that can be checked or derived without Neo4j is done here, so a log that cannot be
stored is refused before the database is touched, and the writes are plain batches:

- ``events``: one row per event with its Neo4j property names (``activity``, ``timestamp`` ...);
  the row position is the event's order in the log.
- ``entities``: ``type``, ``id`` of every entity the chosen entity columns mention.
- ``corr``: ``event``, ``entity`` (row positions) for each CORR edge.
- ``df``: ``source``, ``target`` (event positions), ``entityType``, ``entityId``: consecutive
  events of one entity in one case, ordered by time and then by their order in the log.
- ``comm``: ``source``, ``target``, ``msgId``: from each send event to each receive event of
  the same message in the same case.
- ``starts``: ``event``, ``entity``: where each entity begins in each case (the first event of
  its chain, the one no DF edge of that entity leads to).

:func:`class_tables` aggregates them by a key (``activity``, ``activity+robot``): the classes,
the class of each event (OBSERVED), DF_C with counts and durations, and the entry classes,
so the class graph is written with the events instead of computed by a second pass in Neo4j.

A case is one run of the robots: directly-follows and messages never cross from one run to
another, even where runs reuse message ids or overlap in time (simulated runs all start at
the same instant).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
import pandas as pd

from robotale.errors import InputError
from robotale.eventlog import schema

#: canonical column -> Neo4j property of an Event (other columns keep their names).
EVENT_PROPERTIES: dict[str, str] = {
    schema.CASE: "case",
    schema.ACTIVITY: "activity",
    schema.TIMESTAMP: "timestamp",
    schema.LIFECYCLE: "lifecycle",
    schema.STATE: "state",
    schema.EVENT_ID: "id",
}
#: properties robotale sets itself; a column of that name would overwrite them.
RESERVED = ("log", "order")
# A cell may name several entities: "tractor_1, tractor_2".
_SEPARATOR = ","


@dataclass(frozen=True)
class GraphTables:
    events: pd.DataFrame
    entities: pd.DataFrame
    corr: pd.DataFrame
    df: pd.DataFrame
    comm: pd.DataFrame
    starts: pd.DataFrame
    first: int = 0  # the position of the first event in the stored log (> 0 when appended)


@dataclass(frozen=True)
class ClassTables:
    """The classes of one aggregation key and what connects them (rows refer to positions)."""

    type: str
    key: list[str]
    classes: pd.DataFrame  # ``id`` and the key's properties, one row per class
    observed: np.ndarray  # the class row of each event
    df_c: pd.DataFrame  # ``source``, ``target``, ``entityType``, ``count``, ``meanSeconds``, ...
    entries: pd.DataFrame  # ``entity``, ``class``, ``cases``: where entities begin, how often


def property_name(column: str) -> str:
    """The Event property a log column becomes (``concept:name`` -> ``activity``)."""
    return EVENT_PROPERTIES.get(column, schema.CSV_NAMES.get(column, column))


def check_name(name: object, what: str) -> str:
    """``name`` if it can be a property / type name, else an :class:`InputError`."""
    if not isinstance(name, str) or not schema.is_property_name(name):
        raise InputError(
            f"The {what} {name!r} cannot be used as a Neo4j name: use letters, digits, "
            "_ : . - and blanks, starting with a letter."
        )
    return name


def graph_tables(log: pd.DataFrame, entities: Sequence[str], first: int = 0) -> GraphTables:
    """Check ``log`` (a canonical event log) and derive the tables of its EKG; ``first`` is
    the position its first event takes in the stored log (the number of events already
    stored when it is appended)."""
    events = event_table(log, first)
    types = entity_types([property_name(c) for c in log.columns], entities)
    corr_ids = _correlations(events, types)
    if len(events) and corr_ids.empty:
        raise InputError(
            f"None of the log's {len(events)} events has a value in its entity column(s) "
            f"{', '.join(types)}, so no entity and no DF edge would be built; name the columns "
            "that identify what the events belong to with --entities (e.g. --entities case)."
        )
    entity_table = corr_ids[["type", "id"]].drop_duplicates().reset_index(drop=True)
    position = pd.MultiIndex.from_frame(entity_table).get_indexer(
        pd.MultiIndex.from_frame(corr_ids[["type", "id"]])
    )
    corr = pd.DataFrame({"event": corr_ids["event"].to_numpy(), "entity": position})
    df, starts = _directly_follows(events, corr_ids.assign(entity=position))
    return GraphTables(
        events=events,
        entities=entity_table,
        corr=corr,
        df=df,
        comm=_communication(events),
        starts=starts,
        first=first,
    )


def event_table(log: pd.DataFrame, first: int = 0) -> pd.DataFrame:
    """The events with Neo4j property names, checked, in log order."""
    for column in schema.REQUIRED:
        if column not in log.columns:
            raise InputError(f"The event log has no {schema.CSV_NAMES[column]!r} column.")
    if log.empty:
        raise InputError("The event log has no events.")
    events = log.rename(columns={c: property_name(c) for c in log.columns})
    for column in events.columns:
        check_name(column, "column name")
        if column in RESERVED:
            raise InputError(
                f"The column {column!r} would overwrite the event's own {column!r}; rename it."
            )
    duplicated = events.columns[events.columns.duplicated()].tolist()
    if duplicated:
        raise InputError(
            f"Two columns of the event log both become the property "
            f"{duplicated[0]!r}; keep one of them."
        )
    _check_timestamps(events["timestamp"])
    events = events.reset_index(drop=True)
    if "id" not in events.columns:
        events["id"] = [str(i) for i in range(first, first + len(events))]
    events["id"] = events["id"].astype("string")
    if events["id"].isna().any() or events["id"].duplicated().any():
        bad = events["id"][events["id"].isna() | events["id"].duplicated()].iloc[0]
        raise InputError(
            f"The event id {bad!r} is missing or not unique; event ids must be unique."
        )
    events[schema.MSG_ROLE] = schema.message_roles(log).to_numpy()
    return events


def entity_types(
    columns: Sequence[str], entities: Sequence[str], what: str = "use as an entity type"
) -> list[str]:
    """``entities`` as Event property names, each checked to be one of ``columns``."""
    types = []
    for entity in entities:
        name = property_name(entity.strip())
        if name not in columns:
            available = ", ".join(sorted(c for c in columns if c != "timestamp"))
            raise InputError(
                f"The event log has no column {entity.strip()!r} to {what}; "
                f"its columns are {available}."
            )
        if name not in types:
            types.append(name)
    return types


def entity_ids(values: pd.Series) -> pd.Series:
    """One row per (event position, entity id): cells may hold lists or comma-separated ids."""
    values = values.dropna()
    if values.empty:
        return pd.Series([], dtype="string")
    if _may_hold_lists(values):
        values = values.explode().dropna()
    text = values.astype("string").str.strip()
    if text.str.contains(_SEPARATOR, regex=False).any():
        text = text.str.split(_SEPARATOR).explode().str.strip()
    return text[text != ""]


def _may_hold_lists(values: pd.Series) -> bool:
    """Whether some cell of ``values`` is a list of ids. Asking each cell costs a Python call
    per event; a column pandas infers to hold plain strings or numbers (the usual log)
    holds no list."""
    if pd.api.types.infer_dtype(values, skipna=True) in _SCALARS:
        return False
    return bool(values.map(lambda v: isinstance(v, list | tuple | set | np.ndarray)).any())


#: what :func:`pandas.api.types.infer_dtype` says of a column of plain values
_SCALARS = frozenset({"string", "integer", "floating", "mixed-integer-float", "boolean"})


def _check_timestamps(times: pd.Series) -> None:
    if not pd.api.types.is_datetime64_any_dtype(times) or times.dt.tz is None:
        raise InputError("The event log's timestamps must be timezone-aware datetimes.")
    if times.isna().any():
        raise InputError(f"The event log has no timestamp in row {int(times.isna().argmax())}.")


def _correlations(events: pd.DataFrame, types: list[str]) -> pd.DataFrame:
    parts = []
    for entity_type in types:
        ids = entity_ids(events[entity_type])
        parts.append(
            pd.DataFrame({"event": ids.index.to_numpy(), "type": entity_type, "id": ids.to_numpy()})
        )
    if not parts:
        return pd.DataFrame(
            {
                "event": pd.Series(dtype=int),
                "type": pd.Series(dtype="string"),
                "id": pd.Series(dtype="string"),
            }
        )
    corr = pd.concat(parts, ignore_index=True)
    corr["type"] = corr["type"].astype("string")
    corr["id"] = corr["id"].astype("string")
    return corr.drop_duplicates(["event", "type", "id"]).reset_index(drop=True)


def _directly_follows(
    events: pd.DataFrame, corr: pd.DataFrame
) -> tuple[pd.DataFrame, pd.DataFrame]:
    """DF edges, and the events that begin each entity's chain in each case."""
    # as naive UTC datetime64: a zone-aware column's to_numpy() is one object per event
    times = events["timestamp"].dt.tz_convert("UTC").dt.tz_localize(None)
    at = corr["event"].to_numpy()
    event = at.astype(np.int64)
    # sorted by type, id, case and time as integers (each text's rank among its values) in
    # one lexsort: sorting the texts themselves costs several times more. Sorting by event
    # position last makes the log order break ties between equal times.
    kinds, ids = _ranks(corr["type"]), _ranks(corr["id"])
    cases = _ranks(pd.Series(events["case"].astype("string").to_numpy()[at]))
    order = np.lexsort((event, times.to_numpy().view(np.int64)[at], cases, ids, kinds))
    kinds, ids, cases = kinds[order], ids[order], cases[order]
    # two rows follow each other when type, id and case are equal (a missing case never is)
    same = np.zeros(len(order), dtype=bool)
    same[:-1] = (kinds[1:] == kinds[:-1]) & (ids[1:] == ids[:-1]) & (cases[1:] == cases[:-1])
    same[:-1] &= cases[:-1] != _MISSING
    ordered_event = event[order]
    sources = order[same]
    df = pd.DataFrame(
        {
            "source": ordered_event[same],
            "target": ordered_event[1:][same[:-1]],
            "entityType": corr["type"].to_numpy()[sources],
            "entityId": corr["id"].to_numpy()[sources],
        }
    )
    # A chain begins where no DF edge arrives: the first row, and every row after a last one.
    begins = np.concatenate([[True], ~same[:-1]]) if len(same) else same
    return df, pd.DataFrame(
        {"event": ordered_event[begins], "entity": corr["entity"].to_numpy()[order[begins]]}
    )


#: the rank :func:`_ranks` gives a missing value: after every other
_MISSING = np.iinfo(np.int64).max


def _ranks(values: pd.Series) -> np.ndarray:
    """Each value's rank among the distinct values in pandas' sort order (missing last)."""
    factorized, _ = pd.factorize(values, sort=True)
    codes: np.ndarray = factorized.astype(np.int64)
    codes[codes < 0] = _MISSING
    return codes


def communication_roles(events: pd.DataFrame) -> np.ndarray:
    """Which events send and receive messages, for COMM edges.

    In a log that names its message activities as the thesis does (``weed_position!``,
    ``weed_position?``) those names decide: its other events may carry a message's fields
    without passing it on (the thesis' ``select_closest_tractor``). A log without that
    convention relies on ``msg_role``.
    """
    names = events["activity"].astype("string")
    if names.str.endswith(("!", "?")).fillna(False).any():
        roles_named: np.ndarray = schema.message_roles(
            pd.DataFrame({schema.ACTIVITY: names})
        ).to_numpy()
        return roles_named
    roles = events[schema.MSG_ROLE]
    given: np.ndarray = roles.astype(object).where(roles.notna(), None).to_numpy()
    return given


def _communication(events: pd.DataFrame) -> pd.DataFrame:
    if schema.MSG_ID not in events.columns:
        return pd.DataFrame(columns=["source", "target", "msgId"])
    ids = entity_ids(events[schema.MSG_ID])
    roles = communication_roles(events)[ids.index.to_numpy()]
    at = ids.index.to_numpy()
    messages = pd.DataFrame(
        {
            "event": at,
            "msgId": ids.to_numpy(),
            "case": events["case"].astype("string").to_numpy()[at],
            "role": roles,
        }
    )
    sends = messages[messages["role"] == schema.SEND]
    receives = messages[messages["role"] == schema.RECEIVE]
    pairs = sends.merge(receives, on=["case", "msgId"], suffixes=("_send", "_receive"))
    return pd.DataFrame(
        {
            "source": pairs["event_send"].to_numpy(),
            "target": pairs["event_receive"].to_numpy(),
            "msgId": pairs["msgId"].to_numpy(),
        }
    )


def class_tables(tables: GraphTables, key: Sequence[str]) -> ClassTables:
    """The classes of ``key`` (Event property names) and their DF_C and entry edges.

    A class's id joins its key values with ``|`` (``move|tractor_1``, a missing value as
    nothing), as the Cypher aggregation of a stored log names them. The seconds of a DF edge
    are those between the two events' times to the nanosecond, whole seconds and the
    nanoseconds apart added as the Cypher of a stored log adds them; DF_C's median
    interpolates between the middle two, as ``percentileCont(x, 0.5)`` does.
    """
    events = tables.events
    codes, ids = pd.factorize(_class_ids(events, key))
    first = pd.Series(np.arange(len(codes))).groupby(codes).first().to_numpy()
    classes = events[list(key)].iloc[first].reset_index(drop=True).assign(id=ids.to_numpy())
    return ClassTables(
        type="+".join(key),
        key=list(key),
        classes=classes,
        observed=codes,
        df_c=_df_c(tables, codes),
        entries=_entries(tables.starts, codes),
    )


def _class_ids(events: pd.DataFrame, key: Sequence[str]) -> pd.Series:
    parts = [_neo4j_text(events[name]) for name in key]
    ids = parts[0]
    for part in parts[1:]:
        ids = ids + "|" + part
    return ids


def _neo4j_text(values: pd.Series) -> pd.Series:
    """The values as Cypher's ``toString`` writes them, a missing value as ``''``."""
    if pd.api.types.is_bool_dtype(values):
        text = values.map({True: "true", False: "false"})
    elif pd.api.types.is_float_dtype(values):
        text = values.map(lambda v: None if pd.isna(v) else repr(float(v)))
    else:
        text = values.astype("string")
    return text.astype("string").fillna("")


def _seconds_between(events: pd.DataFrame, source: np.ndarray, target: np.ndarray) -> np.ndarray:
    nanos = events["timestamp"].dt.tz_convert("UTC").dt.as_unit("ns").astype("int64").to_numpy()
    seconds, part = np.divmod(nanos, 1_000_000_000)
    between: np.ndarray = (seconds[target] - seconds[source]) + (part[target] - part[source]) / 1e9
    return between


def _df_c(tables: GraphTables, codes: np.ndarray) -> pd.DataFrame:
    df = tables.df
    source, target = df["source"].to_numpy(), df["target"].to_numpy()
    edges = pd.DataFrame(
        {
            "source": codes[source],
            "target": codes[target],
            "entityType": df["entityType"].to_numpy(),
            "seconds": _seconds_between(tables.events, source, target),
        }
    )
    grouped = edges.groupby(["source", "target", "entityType"], sort=True)["seconds"]
    result = grouped.agg(["count", "mean", "median"]).reset_index()
    return result.rename(columns={"mean": "meanSeconds", "median": "medianSeconds"})


def _entries(starts: pd.DataFrame, codes: np.ndarray) -> pd.DataFrame:
    begins = pd.DataFrame({"entity": starts["entity"].to_numpy()})
    begins["class"] = codes[starts["event"].to_numpy()]
    return begins.groupby(["entity", "class"], sort=True).size().rename("cases").reset_index()


#: what the Log node keeps of a log's values (Discover's filters, the Model page's robots)
SUMMARY_PROPERTIES = {
    "cases": "case",
    "robots": "robot",
    "robotTypes": "robot_type",
    "activities": "activity",
}


def log_values(events: pd.DataFrame) -> dict[str, list[str]]:
    """The distinct values of the summary columns, as text, sorted (empty when absent)."""
    found = {}
    for name, column in SUMMARY_PROPERTIES.items():
        values = events[column].dropna() if column in events.columns else pd.Series([])
        found[name] = sorted(values.astype(str).unique().tolist())
    return found
