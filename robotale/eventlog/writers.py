"""Writing a canonical event log as CSV, XES (IEEE 1849) or OCEL 2.0 JSON.

Each writer writes to a temporary file next to the target and renames it into place, so a
failure never leaves a partial file behind. Timestamps are written in UTC with microseconds,
or nanoseconds when the log's times have them (a recording's own resolution).

- CSV: the short column names of :mod:`robotale.eventlog.schema`, one row per event.
- XES: one trace per case; every event carries ``concept:name``, ``time:timestamp``,
  ``lifecycle:transition`` and ``lifecycle:state`` and the other columns as typed attributes
  (``float`` for x, y, z and battery ...), as in the thesis' listing 6.1. Empty values are left
  out, as XES has no null.
- OCEL 2.0 JSON: events linked to objects of three types, ``robot``, ``message`` and ``run``,
  for object-centric tools (pm4py's ``read_ocel2_json``, OCPM tools); an object-centric log
  read with its objects (:mod:`.objects`) is written with those objects instead.
"""

from __future__ import annotations

import itertools
import json
import math
from collections.abc import Iterable, Mapping
from pathlib import Path
from typing import Any, cast

import numpy as np
import pandas as pd
from lxml import etree

from robotale.errors import InputError
from robotale.eventlog import schema
from robotale.eventlog.objects import Objects
from robotale.fame_runtime.manifest import RunManifest
from robotale.files import atomic_file

CASE, TIME, ACTIVITY = schema.CASE, schema.TIMESTAMP, schema.ACTIVITY
_TIME_FORMAT = "%Y-%m-%dT%H:%M:%S.%f+00:00"
_XES_NS = "http://www.xes-standard.org/"
_XES_EXTENSIONS = (
    ("Concept", "concept"),
    ("Time", "time"),
    ("Lifecycle", "lifecycle"),
)
#: OCEL 2.0 objects' static attributes hold from the beginning of time.
_EPOCH = "1970-01-01T00:00:00+00:00"


#: a column of an XES log as written: its key, its XES type and its values, one per row
_XesAttribute = tuple[str, str, list[str | None]]


def check_target(path: str | Path) -> Path:
    """``path`` if a file can be written there: a folder is refused before anything is
    written (a command writing several files checks them all first)."""
    path = Path(path)
    if path.is_dir():
        raise InputError(
            f"{path} is a folder: give the name of the file to write (e.g. {path / 'log.json'})."
        )
    return path


def _target(path: str | Path) -> Path:
    """``path``, with its folder created if need be."""
    path = check_target(path)
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
    except OSError as error:
        raise InputError(f"Cannot write {path}: {error.strerror or error}.") from None
    return path


def _utc_text(times: pd.Series) -> pd.Series:
    """ISO 8601 in UTC: six decimals of the second, or nine in a log whose times have
    nanoseconds (a recording's own resolution), so that every time of a file has one form."""
    utc = times.dt.tz_convert("UTC").dt.as_unit("ns")
    text = utc.dt.strftime(_TIME_FORMAT)
    nanos = utc.dt.nanosecond.to_numpy()
    if not nanos.any():
        return text
    digits = pd.Series(np.char.zfill(nanos.astype(str), 3), index=text.index)
    return text.str.slice(0, 26) + digits.where(utc.notna()) + "+00:00"


def write_csv(log: pd.DataFrame, path: str | Path) -> None:
    """The log as CSV with the short column names (``case``, ``time``, ``activity`` ...)."""
    table = schema.to_csv_names(log)
    table["time"] = _utc_text(log[TIME]).to_numpy()
    if schema.SOURCE_INDEX in table:
        table[schema.SOURCE_INDEX] = _positions(table[schema.SOURCE_INDEX])
    with atomic_file(_target(path)) as file:
        table.to_csv(file, index=False, lineterminator="\n")


def _positions(index: pd.Series) -> pd.Series:
    """Message positions as whole numbers (``3``, not ``3.0``; the column is float only for
    the events that have none), unchanged if they are not positions."""
    numbers = pd.to_numeric(index, errors="coerce")
    known = numbers.dropna()
    if len(known) != index.notna().sum() or not (known == known.round()).all():
        return index
    return numbers.astype("Int64")


# --------------------------------------------------------------------------------------- XES


def xes_type(series: pd.Series) -> str:
    """The XES attribute element a column's values are written as."""
    if pd.api.types.is_bool_dtype(series):
        return "boolean"
    if pd.api.types.is_integer_dtype(series):
        return "int"
    if pd.api.types.is_float_dtype(series):
        return "float"
    if pd.api.types.is_datetime64_any_dtype(series):
        return "date"
    return "string"


def _xes_values(series: pd.Series, kind: str) -> list[str | None]:
    """Each value as XES text, ``None`` where it is missing (XES has no null)."""
    missing = series.isna().to_numpy()
    if kind == "date":
        text = _utc_text(series).to_numpy(object, copy=True)
    elif kind == "float":
        text = np.array([repr(float(v)) for v in series.to_numpy(float)], dtype=object)
    elif kind == "boolean":
        text = np.where(series.to_numpy(bool), "true", "false").astype(object)
    else:
        text = series.astype(str).to_numpy(object, copy=True)
        if kind == "string":
            missing = missing | (text == "")
    text[missing] = None
    values: list[str | None] = text.tolist()
    return values


def write_xes(log: pd.DataFrame, path: str | Path, name: str | None = None) -> None:
    """The log as IEEE 1849 XES: one trace per case, typed event attributes."""
    log = _grouped_by_case(log)
    first = [TIME, ACTIVITY, schema.LIFECYCLE, schema.STATE]
    columns = [c for c in first if c in log] + [c for c in log if c not in (*first, CASE)]
    attributes: list[_XesAttribute] = []
    for column in columns:
        kind = xes_type(log[column])
        attributes.append((column, kind, _xes_values(log[column], kind)))
    cases = log[CASE].astype(str).to_numpy(object)
    bounds = [0, *(np.flatnonzero(cases[1:] != cases[:-1]) + 1).tolist(), len(log)]
    with atomic_file(_target(path), "wb") as file, etree.xmlfile(file, encoding="utf-8") as xml:
        xml.write_declaration()
        with xml.element("log", {"xes.version": "1849-2016"}, nsmap={None: _XES_NS}):
            xml.write("\n")
            for element in _xes_header(name or Path(path).stem):
                xml.write(element, pretty_print=True)
            for start, end in itertools.pairwise(bounds):
                if end > start:
                    xml.write(_xes_trace(cases[start], attributes, start, end), pretty_print=True)


def _grouped_by_case(log: pd.DataFrame) -> pd.DataFrame:
    """The rows of each case together, cases in order of first appearance, rows in order."""
    codes, _ = pd.factorize(log[CASE])
    if (np.diff(codes) >= 0).all():  # codes number cases by first appearance
        return log
    return log.iloc[np.argsort(codes, kind="stable")]


def _xes_header(name: str) -> list[etree._Element]:
    elements = [
        etree.Element(
            "extension",
            name=title,
            prefix=prefix,
            uri=f"http://www.xes-standard.org/{prefix}.xesext",
        )
        for title, prefix in _XES_EXTENSIONS
    ]
    trace_globals = etree.Element("global", scope="trace")
    etree.SubElement(trace_globals, "string", key="concept:name", value="__INVALID__")
    event_globals = etree.Element("global", scope="event")
    etree.SubElement(event_globals, "string", key="concept:name", value="__INVALID__")
    etree.SubElement(event_globals, "date", key="time:timestamp", value=_EPOCH)
    elements += [trace_globals, event_globals]
    elements.append(etree.Element("classifier", name="Activity", keys="concept:name"))
    elements.append(
        etree.Element(
            "classifier", name="Activity and lifecycle", keys="concept:name lifecycle:transition"
        )
    )
    elements.append(etree.Element("string", key="concept:name", value=name))
    return elements


def _xes_trace(case: str, attributes: list[_XesAttribute], start: int, end: int) -> etree._Element:
    trace = etree.Element("trace")
    etree.SubElement(trace, "string", key="concept:name", value=case)
    sub = etree.SubElement
    for row in range(start, end):
        event = sub(trace, "event")
        for key, kind, values in attributes:
            value = values[row]
            if value is None:
                continue
            try:
                sub(event, kind, key=key, value=value)
            except ValueError:  # lxml refuses what XML 1.0 cannot hold (control characters)
                raise InputError(
                    f"The {key} of event {_event_name(attributes, row)} in {case} ({value!r}) "
                    "cannot be written as XML: it holds a control character."
                ) from None
    return trace


def _event_name(attributes: list[_XesAttribute], row: int) -> str:
    ids = [values for key, _, values in attributes if key == schema.EVENT_ID]
    return str(ids[0][row]) if ids else f"#{row}"


# ---------------------------------------------------------------------------------- OCEL 2.0

_OCEL_TYPES = {"float": "float", "int": "integer", "boolean": "boolean", "date": "time"}
#: log columns that become objects or the event's own fields, not event attributes
_OCEL_STRUCTURE = {CASE, TIME, ACTIVITY, schema.ROBOT, schema.ROBOT_TYPE, schema.EVENT_ID}
_OCEL_MESSAGE = {schema.MSG_ID, schema.MSG_PAYLOAD}
_OCEL_OBJECTS = (schema.ROBOT, schema.MSG_ID)


def write_ocel(
    log: pd.DataFrame,
    path: str | Path,
    runs: Mapping[str, RunManifest] | None = None,
    objects: Objects | None = None,
) -> None:
    """The log as OCEL 2.0 JSON with objects ``robot``, ``message`` and ``run``, or, for an
    object-centric log, with its own ``objects``.

    A robot object is one robot in one run (``drone@run_0001``), a message one message of a
    run (``m52@run_0001``); ``runs`` (case -> manifest) gives run objects their attributes.
    Each event is related to its robot (``performed by``), its run (``in run``) and, for a
    message event, its message (qualified ``send`` or ``receive``).
    """
    if objects is not None:
        document = _object_centric_document(log, objects)
        with atomic_file(_target(path)) as file:
            json.dump(document, file, ensure_ascii=False, allow_nan=False)
        return
    # A log may name no robots or messages at all (any CSV read as a log): none are objects.
    log = log.assign(
        **{
            c: pd.Series(pd.NA, index=log.index, dtype="string")
            for c in _OCEL_OBJECTS
            if c not in log
        }
    )
    events, event_types = _ocel_events(log)
    document = {
        "objectTypes": _ocel_object_types(runs or {}),
        "eventTypes": event_types,
        "objects": _ocel_robots(log) + _ocel_messages(log) + _ocel_runs(log, runs or {}),
        "events": events,
    }
    with atomic_file(_target(path)) as file:
        json.dump(document, file, ensure_ascii=False, allow_nan=False)


def _ids(log: pd.DataFrame, column: str) -> np.ndarray:
    """Object ids of a column's values, scoped to their run: ``drone@run_0001``."""
    values = log[column].astype(object)
    present = values.notna() & (values.astype(str) != "")
    ids = values.astype(str) + "@" + log[CASE].astype(str)
    # numpy's stubs take three Series for the one-argument form: the ids, or None
    return cast(np.ndarray, np.where(present, ids, None))


def _ocel_events(log: pd.DataFrame) -> tuple[list[dict[str, Any]], list[dict[str, Any]]]:
    attributes = [c for c in log if c not in _OCEL_STRUCTURE | _OCEL_MESSAGE]
    kinds = {c: xes_type(log[c]) for c in attributes}
    values = {c: _json_values(log[c], kinds[c]) for c in attributes}
    robots, messages = _ids(log, schema.ROBOT), _ids(log, schema.MSG_ID)
    roles = schema.message_roles(log).to_numpy(object)
    times = _utc_text(log[TIME]).tolist()
    event_ids = (
        log[schema.EVENT_ID].astype(str).tolist()
        if schema.EVENT_ID in log
        else [f"e{i}" for i in range(len(log))]
    )
    activities = log[ACTIVITY].astype(str).tolist()
    cases = log[CASE].astype(str).tolist()
    events = []
    for row, event_id in enumerate(event_ids):
        relationships = [{"objectId": cases[row], "qualifier": "in run"}]
        if robots[row] is not None:
            relationships.append({"objectId": robots[row], "qualifier": "performed by"})
        if messages[row] is not None:
            relationships.append({"objectId": messages[row], "qualifier": roles[row] or "message"})
        events.append(
            {
                "id": event_id,
                "type": activities[row],
                "time": times[row],
                "attributes": [
                    {"name": c, "value": values[c][row]}
                    for c in attributes
                    if values[c][row] is not None
                ],
                "relationships": relationships,
            }
        )
    declared = [{"name": c, "type": _OCEL_TYPES.get(kinds[c], "string")} for c in attributes]
    event_types = [{"name": a, "attributes": declared} for a in sorted(set(activities))]
    return events, event_types


def _json_values(series: pd.Series, kind: str) -> list[Any]:
    if kind in ("string", "date"):
        return _xes_values(series, kind)
    values = series.astype(object).where(series.notna(), None).tolist()
    if kind == "float":
        return [None if v is None or math.isnan(v) else float(v) for v in values]
    if kind == "int":
        return [None if v is None else int(v) for v in values]
    return [None if v is None else bool(v) for v in values]


def _ocel_object_types(runs: Mapping[str, RunManifest]) -> list[dict[str, Any]]:
    run_attributes = sorted({key for manifest in runs.values() for key in _flat(manifest)})

    def string(names: Iterable[str]) -> list[dict[str, str]]:
        return [{"name": n, "type": "string"} for n in names]

    return [
        {"name": "robot", "attributes": string(["name", "robot_type"])},
        {"name": "message", "attributes": string(["msg_id", "payload"])},
        {"name": "run", "attributes": string(run_attributes)},
    ]


def _ocel_robots(log: pd.DataFrame) -> list[dict[str, Any]]:
    columns = [CASE, schema.ROBOT] + ([schema.ROBOT_TYPE] if schema.ROBOT_TYPE in log else [])
    named = log[schema.ROBOT].notna() & (log[schema.ROBOT].astype(str) != "")
    robots = log.loc[named, columns].drop_duplicates([CASE, schema.ROBOT])
    objects = []
    for row in robots.itertuples(index=False):
        case, robot = str(row[0]), str(row[1])
        attributes = [{"name": "name", "time": _EPOCH, "value": robot}]
        if len(row) > 2 and isinstance(row[2], str):
            attributes.append({"name": "robot_type", "time": _EPOCH, "value": row[2]})
        objects.append(
            {
                "id": f"{robot}@{case}",
                "type": "robot",
                "attributes": attributes,
                "relationships": [{"objectId": case, "qualifier": "part of"}],
            }
        )
    return objects


def _ocel_messages(log: pd.DataFrame) -> list[dict[str, Any]]:
    if schema.MSG_ID not in log:
        return []
    messages = log.assign(_object=_ids(log, schema.MSG_ID), _robot=_ids(log, schema.ROBOT))
    messages = messages[messages["_object"].notna()]
    roles = schema.message_roles(messages)
    objects = []
    for object_id, group in messages.groupby("_object", sort=True):
        first = group.iloc[0]
        attributes = [{"name": "msg_id", "time": _EPOCH, "value": str(first[schema.MSG_ID])}]
        payload = group.get(schema.MSG_PAYLOAD, pd.Series(dtype=object)).dropna()
        if len(payload) and str(payload.iloc[0]):
            attributes.append({"name": "payload", "time": _EPOCH, "value": str(payload.iloc[0])})
        relationships = [{"objectId": str(first[CASE]), "qualifier": "part of"}]
        for role, qualifier in (("send", "sent by"), ("receive", "received by")):
            robots = group.loc[roles.loc[group.index] == role, "_robot"].dropna().unique()
            relationships += [{"objectId": r, "qualifier": qualifier} for r in sorted(robots)]
        objects.append(
            {
                "id": object_id,
                "type": "message",
                "attributes": attributes,
                "relationships": relationships,
            }
        )
    return objects


def _ocel_runs(log: pd.DataFrame, runs: Mapping[str, RunManifest]) -> list[dict[str, Any]]:
    objects = []
    for case in pd.unique(log[CASE].astype(str)):
        flat = _flat(runs.get(case, {}))
        attributes = [
            {"name": key, "time": _EPOCH, "value": value} for key, value in sorted(flat.items())
        ]
        objects.append({"id": case, "type": "run", "attributes": attributes})
    return objects


def _flat(manifest: Mapping[str, Any], prefix: str = "") -> dict[str, str]:
    """A manifest's values as text, nested keys joined with dots (``outcome.status``)."""
    flat: dict[str, str] = {}
    for key, value in manifest.items():
        if isinstance(value, Mapping):
            flat.update(_flat(value, f"{prefix}{key}."))
        elif value is not None:
            flat[f"{prefix}{key}"] = value if isinstance(value, str) else json.dumps(value)
    return flat


# -- OCEL 2.0 of an object-centric log ------------------------------------------------------


def _object_centric_document(log: pd.DataFrame, objects: Objects) -> dict[str, Any]:
    """The OCEL 2.0 document of a log read with its objects: its events with their own
    attributes, its objects with theirs and their changes, and the relations between them."""
    attributes = _event_attributes(log, objects)
    kinds = {c: xes_type(log[c]) for c in attributes}
    values = {c: _json_values(log[c], kinds[c]) for c in attributes}
    event_ids = log[schema.EVENT_ID].astype(str).tolist()
    activities = log[ACTIVITY].astype(str).tolist()
    times = _utc_text(log[TIME]).tolist()
    links = objects.e2o.groupby("event", sort=False)
    relationships = {
        str(event): [
            {"objectId": str(o), "qualifier": "" if pd.isna(q) else str(q)}
            for o, q in zip(group["object"], group["qualifier"], strict=True)
        ]
        for event, group in links
    }
    events = []
    declared: dict[str, dict[str, str]] = {}
    for row, event_id in enumerate(event_ids):
        present = [c for c in attributes if values[c][row] is not None]
        kind = declared.setdefault(activities[row], {})
        kind.update({c: _OCEL_TYPES.get(kinds[c], "string") for c in present})
        events.append(
            {
                "id": event_id,
                "type": activities[row],
                "time": times[row],
                "attributes": [{"name": c, "value": values[c][row]} for c in present],
                "relationships": relationships.get(event_id, []),
            }
        )
    object_types, listed = _listed_objects(objects)
    return {
        "objectTypes": object_types,
        "eventTypes": [
            {"name": name, "attributes": [{"name": a, "type": t} for a, t in sorted(kind.items())]}
            for name, kind in sorted(declared.items())
        ],
        "objects": listed,
        "events": events,
    }


def _event_attributes(log: pd.DataFrame, objects: Objects) -> list[str]:
    """The log's columns that are event attributes: not the event's own fields, not object
    columns, and not the case and lifecycle robotale fills in where a log has none."""
    structure = {schema.EVENT_ID, ACTIVITY, TIME, *objects.entity_types}
    filled = {CASE: "1", schema.LIFECYCLE: schema.COMPLETE}
    for column, value in filled.items():
        if column in log and (log[column].astype("string") == value).all():
            structure.add(column)
    return [c for c in log.columns if c not in structure]


def _listed_objects(objects: Objects) -> tuple[list[dict[str, Any]], list[dict[str, Any]]]:
    table = objects.objects
    changes = objects.changes.groupby("object", sort=False)
    changed = {str(o): group for o, group in changes}
    related = {str(o): group for o, group in objects.o2o.groupby("source", sort=False)}
    types: dict[str, dict[str, str]] = {}
    listed = []
    for _, row in table.iterrows():
        object_id, kind = str(row["id"]), str(row["type"])
        declared = types.setdefault(kind, {})
        attributes = []
        for name in objects.attributes:
            value = _json_value(row[name])
            if value is not None:
                declared[name] = _json_type(value)
                attributes.append({"name": name, "time": _EPOCH, "value": value})
        if object_id in changed:
            for change in changed[object_id].itertuples(index=False):
                value = _json_value(change.value)
                declared.setdefault(change.field, _json_type(value))
                time = pd.Timestamp(change.time).tz_convert("UTC").strftime(_TIME_FORMAT)
                attributes.append({"name": change.field, "time": time, "value": value})
        entry = {"id": object_id, "type": kind, "attributes": attributes}
        if object_id in related:
            group = related[object_id]
            entry["relationships"] = [
                {"objectId": str(t), "qualifier": "" if pd.isna(q) else str(q)}
                for t, q in zip(group["target"], group["qualifier"], strict=True)
            ]
        listed.append(entry)
    object_types = [
        {"name": kind, "attributes": [{"name": a, "type": t} for a, t in sorted(names.items())]}
        for kind, names in types.items()
    ]
    return object_types, listed


def _json_value(value: object) -> object:
    """A cell as a JSON value (None where it is missing)."""
    if value is None or (not isinstance(value, str | list) and pd.isna(value)):
        return None
    if isinstance(value, np.generic):
        return value.item()
    if isinstance(value, pd.Timestamp):
        return value.tz_convert("UTC").strftime(_TIME_FORMAT) if value.tzinfo else value.isoformat()
    return value


def _json_type(value: object) -> str:
    if isinstance(value, bool):
        return "boolean"
    if isinstance(value, int):
        return "integer"
    if isinstance(value, float):
        return "float"
    return "string"
