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
- ``follows``: ``source``, ``target``, ``entityType``: consecutive activity instances of one
  entity in one case. An activity instance is counted once, by the event that ends it (a
  completion, an aborted or cancelled end, or an instant event); a start and an in-progress
  sample (continuous data between them) are never instances, so DF_C counts instances as
  pm4py's DFG of the activity instances does, not the samples recorded while one ran.

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
import pyarrow as pa
import pyarrow.compute as pc

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
    #: ``source``, ``target`` (event positions), ``entityType``: consecutive activity
    #: instances of one entity in one case (see :func:`instance_ends`), what DF_C aggregates
    follows: pd.DataFrame
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


def graph_tables(
    log: pd.DataFrame, entities: Sequence[str], first: int = 0, lifting: bool = False
) -> GraphTables:
    """Check ``log`` (a canonical event log) and derive the tables of its EKG; ``first`` is
    the position its first event takes in the stored log (the number of events already
    stored when it is appended). ``lifting``: only what an aggregation lifts (``df`` with
    ``source``, ``target`` and ``entity``, the entity's row, instead of its type and id as
    text; no ``follows``): the texts and the instances' chains cost a million-event log's
    aggregation a second of its reading."""
    events = event_table(log, first)
    types = entity_types([property_name(c) for c in log.columns], entities)
    corr, entity_table = _correlations(events, types)
    if len(events) and corr.empty:
        raise InputError(
            f"None of the log's {len(events)} events has a value in its entity column(s) "
            f"{', '.join(types)}, so no entity and no DF edge would be built; name the columns "
            "that identify what the events belong to with --entities (e.g. --entities case)."
        )
    df, starts, follows = _directly_follows(events, corr, entity_table, lifting)
    return GraphTables(
        events=events,
        entities=entity_table,
        corr=corr,
        df=df,
        comm=_communication(events),
        starts=starts,
        first=first,
        follows=follows,
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
    # is_unique costs about half of duplicated(), which only the message needs
    if events["id"].isna().any() or not events["id"].is_unique:
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
    # split and trimmed by Arrow in one pass: a Python split per cell cost seconds per
    # million events, most of the aggregation's reading of a log with several ids per cell
    cells = pa.array(values.astype("string").array)
    parts = pc.split_pattern(cells, _SEPARATOR)
    at = pc.list_parent_indices(parts).to_numpy()
    text = pd.Series(
        pd.array(pc.utf8_trim_whitespace(pc.list_flatten(parts)), dtype="string"),
        index=values.index[at],
    )
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


def _correlations(events: pd.DataFrame, types: list[str]) -> tuple[pd.DataFrame, pd.DataFrame]:
    """The CORR rows (``event``, ``entity``: positions in the events and in the entity table)
    and the entity table (``type``, ``id``, in the order the events first name them)."""
    corr, entities, known = [], [], 0
    for entity_type in types:
        ids = entity_ids(events[entity_type])
        codes, uniques = pd.factorize(ids)
        event = ids.index.to_numpy().astype(np.int64)
        if ids.index.has_duplicates:  # a cell that names one entity twice: one CORR edge
            _, unique_rows = np.unique(event * len(uniques) + codes, return_index=True)
            keep = np.sort(unique_rows)
            event, codes = event[keep], codes[keep]
        corr.append(pd.DataFrame({"event": event, "entity": codes.astype(np.int64) + known}))
        entities.append(pd.DataFrame({"type": entity_type, "id": np.asarray(uniques, object)}))
        known += len(uniques)
    if not corr:
        corr.append(pd.DataFrame({"event": pd.Series(dtype=np.int64), "entity": 0}))
        entities.append(pd.DataFrame({"type": pd.Series(dtype=object), "id": None}))
    entity_table = pd.concat(entities, ignore_index=True).astype("string")
    return pd.concat(corr, ignore_index=True), entity_table


def _directly_follows(
    events: pd.DataFrame, corr: pd.DataFrame, entities: pd.DataFrame, lifting: bool = False
) -> tuple[pd.DataFrame, pd.DataFrame, pd.DataFrame]:
    """DF edges, the events that begin each entity's chain in each case, and the DF edges of
    the activity instances (the chains without the events that end no instance; none when
    ``lifting``, whose DF edges name their entity by its row, :func:`graph_tables`)."""
    event = corr["event"].to_numpy().astype(np.int64)
    entity = corr["entity"].to_numpy().astype(np.int64)
    # one integer per entity and case: two rows are in one chain when it is equal (a missing
    # case is in none); integers sort several times faster than the texts they stand for
    cases, names = pd.factorize(events["case"].astype("string"))
    case = cases.astype(np.int64)[event]
    chain = entity * (len(names) + 1) + case
    chain[case < 0] = -1 - np.arange(int((case < 0).sum()))  # each a chain of its own
    order = _chain_order(event, chain, utc_ticks(events))
    ordered_event, ordered_entity, ordered_chain = event[order], entity[order], chain[order]
    same = ordered_chain[1:] == ordered_chain[:-1]
    # each entity's type and id taken from the entity table's own arrays: an array of
    # Python strings would be converted into one again, which costs more than the rest
    kinds = entities["type"].array
    sources = ordered_entity[:-1][same]
    # A chain begins where no DF edge arrives: the first row, and every row after a last one.
    begins = np.concatenate([[True], ~same]) if len(order) else np.zeros(0, dtype=bool)
    starts = pd.DataFrame({"event": ordered_event[begins], "entity": ordered_entity[begins]})
    if lifting:
        lifted = {"source": ordered_event[:-1][same], "target": ordered_event[1:][same]}
        return pd.DataFrame(lifted | {"entity": sources}), starts, pd.DataFrame()
    df = pd.DataFrame(
        {
            "source": ordered_event[:-1][same],
            "target": ordered_event[1:][same],
            "entityType": kinds.take(sources),
            "entityId": entities["id"].array.take(sources),
        }
    )
    return (
        df,
        starts,
        _instance_follows(events, ordered_event, ordered_entity, ordered_chain, kinds),
    )


def _chain_order(event: np.ndarray, chain: np.ndarray, ticks: np.ndarray) -> np.ndarray:
    """The order of the rows by chain, then their event's time, then its position (the log
    order breaks ties between equal times). The events are ranked by time and position once
    and each row sorted by one integer, chain and rank: a lexsort of three keys over the
    rows (several per event) cost most of the edges' derivation."""
    count = len(ticks)
    widest = max(int(chain.max()) + 1, -int(chain.min())) if len(chain) else 0
    if widest * count >= 2**62:  # the integer would not fit
        return np.lexsort((event, ticks[event], chain))
    rank = np.empty(count, dtype=np.int64)
    rank[np.argsort(ticks, kind="stable")] = np.arange(count)
    key = chain * count + rank[event]
    return np.argsort(key, kind="stable")


def _instance_follows(
    events: pd.DataFrame,
    ordered_event: np.ndarray,
    ordered_entity: np.ndarray,
    ordered_chain: np.ndarray,
    kinds: pd.api.extensions.ExtensionArray,
) -> pd.DataFrame:
    """Consecutive activity instances of each chain: the chains in their order, without the
    events that end no instance."""
    kept = instance_ends(events)[ordered_event]
    event, entity, chain = ordered_event[kept], ordered_entity[kept], ordered_chain[kept]
    same = chain[1:] == chain[:-1]
    return pd.DataFrame(
        {
            "source": event[:-1][same],
            "target": event[1:][same],
            "entityType": kinds.take(entity[:-1][same]),
        }
    )


def instance_ends(events: pd.DataFrame) -> np.ndarray:
    """Which events end an activity instance: every event but a start (lifecycle ``start``)
    and an in-progress sample (state ``inprogress``), as ``cypher/discover_classes.cypher``
    and ``cypher/ekg_aggregate_df_c.cypher`` tell them in a stored log."""
    ends = np.ones(len(events), dtype=bool)
    for column, value in (("lifecycle", schema.START), ("state", schema.INPROGRESS)):
        if column in events.columns:
            # a log repeats a handful of values: compare each distinct one once
            codes, uniques = pd.factorize(events[column])
            matches = np.append(np.asarray(uniques, dtype=object) == value, False)
            ends &= ~matches[codes]
    return ends


def utc_ticks(events: pd.DataFrame) -> np.ndarray:
    """The events' times as nanoseconds since the epoch (UTC), compared as integers."""
    times = events["timestamp"].dt.tz_convert("UTC").dt.as_unit("ns")
    ticks: np.ndarray = (
        times.array.asi8 if hasattr(times.array, "asi8") else times.astype("int64").to_numpy()
    )
    return ticks


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
    codes = _class_codes(events, key)
    first = np.zeros(int(codes.max()) + 1 if len(codes) else 0, dtype=np.int64)
    first[codes[::-1]] = np.arange(len(codes))[::-1]  # each class's first event
    ids = _class_ids(events.iloc[first], key)
    if ids.duplicated().any():  # values told apart whose texts are the same: one class
        codes, unique_ids = pd.factorize(_class_ids(events, key))
        first = pd.Series(np.arange(len(codes))).groupby(codes).first().to_numpy()
        ids = pd.Series(unique_ids)
    classes = events[list(key)].iloc[first].reset_index(drop=True).assign(id=ids.to_numpy())
    return ClassTables(
        type="+".join(key),
        key=list(key),
        classes=classes,
        observed=codes,
        df_c=_df_c(tables, codes),
        entries=_entries(tables.starts, codes),
    )


def _class_codes(events: pd.DataFrame, key: Sequence[str]) -> np.ndarray:
    """Each event's class, numbered in the order the classes first appear. The key's values
    are compared as they are: writing every value as text first costs several times more
    (values of mixed types, compared as objects, are compared as their text)."""
    combined = np.zeros(len(events), dtype=np.int64)
    for name in key:
        values = events[name]
        if pd.api.types.is_object_dtype(values):
            values = _neo4j_text(values)
        codes, uniques = pd.factorize(values, use_na_sentinel=False)
        combined = pd.factorize(combined * len(uniques) + codes)[0].astype(np.int64)
    numbered: np.ndarray = pd.factorize(combined)[0]
    return numbered


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
    seconds, part = np.divmod(utc_ticks(events), 1_000_000_000)
    between: np.ndarray = (seconds[target] - seconds[source]) + (part[target] - part[source]) / 1e9
    return between


def _df_c(tables: GraphTables, codes: np.ndarray) -> pd.DataFrame:
    """DF_C: the instance DF edges grouped by their classes and entity type, with their
    count and the mean and median seconds between the two instances' ends."""
    follows = tables.follows
    source, target = follows["source"].to_numpy(), follows["target"].to_numpy()
    kinds, names = pd.factorize(follows["entityType"])
    classes = int(codes.max()) + 1 if len(codes) else 0
    # one integer per (source class, target class, entity type): numpy groups it faster than
    # pandas groups three columns
    key = (codes[source].astype(np.int64) * classes + codes[target]) * max(len(names), 1) + kinds
    seconds = _seconds_between(tables.events, source, target)
    # by key, each key's seconds in order (for the median): two argsorts cost half a lexsort
    by_seconds = np.argsort(seconds)
    order = by_seconds[np.argsort(key[by_seconds], kind="stable")]
    key, seconds = key[order], seconds[order]
    first = np.flatnonzero(np.concatenate([[True], key[1:] != key[:-1]])) if len(key) else key
    count = np.diff(np.append(first, len(key)))
    # the median of each group's sorted seconds: the middle one, or halfway between the two
    median = (seconds[first + (count - 1) // 2] + seconds[first + count // 2]) / 2
    groups = key[first]
    pair, kind = np.divmod(groups, max(len(names), 1))
    return pd.DataFrame(
        {
            "source": pair // max(classes, 1),
            "target": pair % max(classes, 1),
            "entityType": np.asarray(names, dtype=object)[kind] if len(names) else kind,
            "count": count,
            "meanSeconds": np.add.reduceat(seconds, first) / count if len(key) else seconds,
            "medianSeconds": median,
        }
    )


def _entries(starts: pd.DataFrame, codes: np.ndarray) -> pd.DataFrame:
    """``entity``, ``class``, ``cases``: how often each entity begins at each class, ordered
    by entity and class (one integer per pair: numpy counts it faster than a pandas groupby,
    a fixed cost each live update pays)."""
    entity = starts["entity"].to_numpy(dtype=np.int64)
    found = codes[starts["event"].to_numpy()].astype(np.int64)
    classes = int(codes.max()) + 1 if len(codes) else 1
    pairs, cases = np.unique(entity * classes + found, return_counts=True)
    return pd.DataFrame(
        {"entity": pairs // classes, "class": pairs % classes, "cases": cases.astype(np.int64)}
    )


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
