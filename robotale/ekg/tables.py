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


def property_name(column: str) -> str:
    """The Event property a log column becomes (``concept:name`` -> ``activity``)."""
    return EVENT_PROPERTIES.get(column, schema.CSV_NAMES.get(column, column))


def check_name(name: object, what: str) -> str:
    """``name`` if it can be a property / type name, else an :class:`InputError`."""
    if not schema.is_property_name(name):
        raise InputError(
            f"The {what} {name!r} cannot be used as a Neo4j name: use letters, digits, "
            "_ : . - and blanks, starting with a letter."
        )
    return name


def graph_tables(log: pd.DataFrame, entities: Sequence[str]) -> GraphTables:
    """Check ``log`` (a canonical event log) and derive the tables of its EKG."""
    events = event_table(log)
    types = entity_types([property_name(c) for c in log.columns], entities)
    corr_ids = _correlations(events, types)
    entity_table = corr_ids[["type", "id"]].drop_duplicates().reset_index(drop=True)
    position = pd.MultiIndex.from_frame(entity_table).get_indexer(
        pd.MultiIndex.from_frame(corr_ids[["type", "id"]])
    )
    corr = pd.DataFrame({"event": corr_ids["event"].to_numpy(), "entity": position})
    return GraphTables(
        events=events,
        entities=entity_table,
        corr=corr,
        df=_directly_follows(events, corr_ids),
        comm=_communication(events),
    )


def event_table(log: pd.DataFrame) -> pd.DataFrame:
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
        events["id"] = [str(i) for i in range(len(events))]
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
    if values.map(lambda v: isinstance(v, list | tuple | set | np.ndarray)).any():
        values = values.explode().dropna()
    text = values.astype("string").str.strip()
    if text.str.contains(_SEPARATOR, regex=False).any():
        text = text.str.split(_SEPARATOR).explode().str.strip()
    return text[text != ""]


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


def _directly_follows(events: pd.DataFrame, corr: pd.DataFrame) -> pd.DataFrame:
    times = events["timestamp"].dt.tz_convert("UTC")
    at = corr["event"].to_numpy()
    ordered = corr.assign(
        time=times.to_numpy()[at], case=events["case"].astype("string").to_numpy()[at]
    )
    # Sorting by event position last makes the log order break ties between equal times.
    ordered = ordered.sort_values(["type", "id", "case", "time", "event"], kind="stable")
    same = np.ones(len(ordered), dtype=bool)
    for key in ("type", "id", "case"):
        same &= (ordered[key].shift(-1) == ordered[key]).fillna(False).to_numpy(bool)
    following = ordered["event"].shift(-1)[same]
    sources = ordered[same]
    return pd.DataFrame(
        {
            "source": sources["event"].to_numpy(),
            "target": following.to_numpy().astype(np.int64),
            "entityType": sources["type"].to_numpy(),
            "entityId": sources["id"].to_numpy(),
        }
    )


def communication_roles(events: pd.DataFrame) -> np.ndarray:
    """Which events send and receive messages, for COMM edges.

    In a log that names its message activities as the thesis does (``weed_position!``,
    ``weed_position?``) those names decide: its other events may carry a message's fields
    without passing it on (the thesis' ``select_closest_tractor``). A log without that
    convention relies on ``msg_role``.
    """
    names = events["activity"].astype("string")
    if names.str.endswith(("!", "?")).fillna(False).any():
        return schema.message_roles(pd.DataFrame({schema.ACTIVITY: names})).to_numpy()
    roles = events[schema.MSG_ROLE]
    return roles.astype(object).where(roles.notna(), None).to_numpy()


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
