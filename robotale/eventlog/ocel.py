"""Read OCEL 2.0 logs (JSON, XML and SQLite) into an :class:`~.objects.ObjectLog`.

The three encodings of the standard say the same things: event and object types with their
attributes, events (id, type, time, attributes, related objects with a qualifier) and objects
(id, type, attributes with the time each value holds from, related objects with a qualifier).
An attribute value of an object at the beginning of time (1970-01-01, or no time in SQLite)
is its value; a later one is a change. Values keep their types (XML's by the declared type).

Every problem is one :class:`~robotale.errors.InputError` naming the file and the element,
line or table row.
"""

from __future__ import annotations

import json
import sqlite3
from collections.abc import Callable, Iterable, Mapping
from pathlib import Path
from typing import Any

import pandas as pd

from robotale.errors import InputError
from robotale.eventlog.objects import (
    CHANGE_COLUMNS,
    E2O_COLUMNS,
    O2O_COLUMNS,
    ObjectLog,
    Objects,
    check_attribute_names,
    check_object_ids,
    require_known_objects,
)

#: file name endings read as OCEL 2.0, by encoding
SUFFIXES = {
    ".jsonocel": "json",
    ".json": "json",
    ".xmlocel": "xml",
    ".xml": "xml",
    ".sqlite": "sqlite",
    ".sqlite3": "sqlite",
    ".db": "sqlite",
}
_EPOCH = pd.Timestamp(0, tz="UTC")
#: the events' own columns, named as pm4py names them (no event attribute is named so)
EVENT_ID, ACTIVITY, TIME = "ocel:eid", "ocel:activity", "ocel:timestamp"


def encoding(path: Path) -> str | None:
    """``json``, ``xml`` or ``sqlite`` when ``path`` is read as OCEL 2.0, else None."""
    return SUFFIXES.get(path.suffix.lower())


def read_ocel(path: Path) -> ObjectLog:
    """The OCEL 2.0 log at ``path``, in the encoding its name says."""
    if not path.exists():
        raise InputError(f"{path} does not exist.")
    if path.is_dir():
        raise InputError(f"{path} is a directory, not an OCEL 2.0 file.")
    reader = {"json": _read_json, "xml": _read_xml, "sqlite": _read_sqlite}[encoding(path) or ""]
    return reader(path)


# -- assembling the tables ---------------------------------------------------------------------


class _Tables:
    """Rows gathered while a file is read, turned into an :class:`ObjectLog` at the end."""

    def __init__(self, path: Path) -> None:
        self.path = path
        self.events: list[dict[str, Any]] = []
        self.objects: list[dict[str, Any]] = []
        self.e2o: list[tuple[str, str, str | None]] = []
        self.o2o: list[tuple[str, str, str | None]] = []
        self.changes: list[tuple[str, pd.Timestamp, str, Any]] = []

    def event(self, where: str, event_id: Any, kind: Any, time: Any, values: dict[str, Any]) -> str:
        for name, given in (("id", event_id), ("type", kind), ("time", time)):
            if given is None or str(given).strip() == "":
                raise InputError(f"{self.path}: {where} has no {name}.")
        check_attribute_names(self.path, list(values), "event")
        at = _time(self.path, where, time)
        self.events.append({EVENT_ID: str(event_id), ACTIVITY: str(kind), TIME: at})
        self.events[-1].update({f"\0{k}": v for k, v in values.items()})
        return str(event_id)

    def object(self, where: str, object_id: Any, kind: Any) -> str:
        for name, given in (("id", object_id), ("type", kind)):
            if given is None or str(given).strip() == "":
                raise InputError(f"{self.path}: {where} has no {name}.")
        self.objects.append({"id": str(object_id), "type": str(kind)})
        return str(object_id)

    def attribute(self, where: str, object_id: str, name: str, time: Any, value: Any) -> None:
        """An object's attribute value holding from ``time`` (None: from the beginning)."""
        check_attribute_names(self.path, [name], "object")
        at = _EPOCH if time is None else _time(self.path, where, time)
        if at == _EPOCH:
            self.objects[-1][f"\0{name}"] = value
        else:
            self.changes.append((object_id, at, name, value))

    def finish(self) -> ObjectLog:
        if not self.events:
            raise InputError(f"{self.path} has no events.")
        events = _with_attributes(pd.DataFrame(self.events))
        repeated = events[EVENT_ID].duplicated()
        if repeated.any():
            raise InputError(
                f"{self.path}: the event id {events[EVENT_ID][repeated].iloc[0]!r} appears more "
                "than once."
            )
        listed = (
            pd.DataFrame(self.objects) if self.objects else pd.DataFrame(columns=["id", "type"])
        )
        objects = _with_attributes(listed)
        objects = objects[["type", "id", *objects.columns.drop(["type", "id"])]]
        check_object_ids(self.path, objects)
        found = Objects(
            objects=objects.reset_index(drop=True),
            e2o=pd.DataFrame(self.e2o, columns=list(E2O_COLUMNS), dtype=object),
            o2o=pd.DataFrame(self.o2o, columns=list(O2O_COLUMNS), dtype=object),
            changes=pd.DataFrame(self.changes, columns=list(CHANGE_COLUMNS)),
        )
        require_known_objects(self.path, found)
        return ObjectLog(events=events, objects=found)


def _with_attributes(table: pd.DataFrame) -> pd.DataFrame:
    """Attribute columns (marked with a leading NUL while gathered) under their own names,
    after the structural ones; a column of numbers and missing values is numeric."""
    names = {c: c[1:] for c in table.columns if c.startswith("\0")}
    table = table.rename(columns=names)
    for column in names.values():
        table[column] = table[column].infer_objects()
    return table


def _time(path: Path, where: str, text: Any) -> pd.Timestamp:
    try:
        stamp = pd.Timestamp(str(text).strip())
    except ValueError:
        stamp = pd.NaT
    if pd.isna(stamp):
        raise InputError(
            f"{path}: {where} has the time {text!r}, which is not an ISO 8601 time "
            "(e.g. 2023-05-16T10:27:08Z)."
        )
    return stamp.tz_localize("UTC") if stamp.tzinfo is None else stamp.tz_convert("UTC")


# -- JSON --------------------------------------------------------------------------------------


def _read_json(path: Path) -> ObjectLog:
    try:
        document = json.loads(path.read_bytes())
    except json.JSONDecodeError as error:
        raise InputError(
            f"{path} is not OCEL 2.0 JSON: {error.msg} (line {error.lineno})."
        ) from None
    except UnicodeDecodeError:
        raise InputError(f"{path} is not OCEL 2.0 JSON: it is not UTF-8 text.") from None
    if not isinstance(document, dict) or not isinstance(document.get("events"), list):
        raise InputError(f'{path} is not OCEL 2.0 JSON: it has no list of "events".')
    tables = _Tables(path)
    for number, item in enumerate(_entries(path, document, "objects"), start=1):
        where = f"object {number} ({item.get('id')!r})"
        object_id = tables.object(where, item.get("id"), item.get("type"))
        for attribute in _list(path, item, "attributes", where):
            tables.attribute(
                where,
                object_id,
                _name(path, attribute, where),
                attribute.get("time"),
                attribute.get("value"),
            )
        for link in _list(path, item, "relationships", where):
            tables.o2o.append((object_id, _target(path, link, where), link.get("qualifier")))
    for number, item in enumerate(_entries(path, document, "events"), start=1):
        where = f"event {number} ({item.get('id')!r})"
        values = {
            _name(path, a, where): a.get("value") for a in _list(path, item, "attributes", where)
        }
        event_id = tables.event(where, item.get("id"), item.get("type"), item.get("time"), values)
        for link in _list(path, item, "relationships", where):
            tables.e2o.append((event_id, _target(path, link, where), link.get("qualifier")))
    return tables.finish()


def _entries(path: Path, document: Mapping[str, Any], key: str) -> list[dict[str, Any]]:
    items = document.get(key) or []
    if not isinstance(items, list):
        raise InputError(f"{path}: the {key} are not a list of JSON objects.")
    for number, item in enumerate(items, start=1):
        if not isinstance(item, dict):
            raise InputError(f"{path}: {key[:-1]} {number} is not a JSON object.")
    return items


def _list(path: Path, item: Mapping[str, Any], key: str, where: str) -> list[dict[str, Any]]:
    values = item.get(key) or []
    if not isinstance(values, list) or not all(isinstance(v, dict) for v in values):
        raise InputError(f"{path}: the {key} of {where} are not a list of JSON objects.")
    return values


def _name(path: Path, attribute: Mapping[str, Any], where: str) -> str:
    name = attribute.get("name")
    if not isinstance(name, str) or not name:
        raise InputError(f"{path}: an attribute of {where} has no name.")
    return name


def _target(path: Path, link: Mapping[str, Any], where: str) -> str:
    target = link.get("objectId")
    if target is None or str(target) == "":
        raise InputError(f"{path}: a relationship of {where} names no objectId.")
    return str(target)


# -- XML ---------------------------------------------------------------------------------------

_XML_VALUES: dict[str, Callable[[str], Any]] = {
    "string": str,
    "time": str,
    "integer": int,
    "float": float,
    "boolean": lambda text: text.strip().lower() in ("true", "1"),
}


def _read_xml(path: Path) -> ObjectLog:
    # here, not at the top: lxml is measured start-up that only an OCEL XML file needs (every
    # ingest imports this module to tell a log's kind)
    from lxml import etree

    parser = etree.XMLParser(resolve_entities=False, no_network=True, huge_tree=True)
    try:
        root = etree.parse(str(path), parser).getroot()
    except etree.XMLSyntaxError as error:
        raise InputError(
            f"{path} is not OCEL 2.0 XML: {error.msg} (line {error.lineno})."
        ) from None
    if _local(root.tag) != "log":
        raise InputError(
            f"{path} line {root.sourceline}: the root is <{_local(root.tag)}>, not <log>."
        )
    event_types = _declared(root, "event-type")
    object_types = _declared(root, "object-type")
    tables = _Tables(path)
    for element in _children(root, "objects", "object"):
        where = f"line {element.sourceline}: the object {element.get('id')!r}"
        object_id = tables.object(where, element.get("id"), element.get("type"))
        kinds = object_types.get(element.get("type"), {})
        for attribute in _children(element, "attributes", "attribute"):
            name = _xml_name(path, attribute)
            value = _xml_value(path, attribute, kinds.get(name, "string"))
            tables.attribute(where, object_id, name, attribute.get("time"), value)
        for link in _children(element, "objects", "relationship"):
            target = _xml_target(path, link)
            tables.o2o.append((object_id, target, link.get("qualifier")))
    for element in _children(root, "events", "event"):
        where = f"line {element.sourceline}: the event {element.get('id')!r}"
        kinds = event_types.get(element.get("type"), {})
        values = {}
        for attribute in _children(element, "attributes", "attribute"):
            name = _xml_name(path, attribute)
            values[name] = _xml_value(path, attribute, kinds.get(name, "string"))
        event_id = tables.event(
            where, element.get("id"), element.get("type"), element.get("time"), values
        )
        for link in _children(element, "objects", "relationship"):
            tables.e2o.append((event_id, _xml_target(path, link), link.get("qualifier")))
    return tables.finish()


def _local(tag: object) -> str:
    return tag.rpartition("}")[2] if isinstance(tag, str) else ""


def _children(element: Any, group: str, tag: str) -> Iterable[Any]:
    for holder in element:
        if _local(holder.tag) == group:
            yield from (child for child in holder if _local(child.tag) == tag)


def _declared(root: Any, tag: str) -> dict[str, dict[str, str]]:
    """Type name -> attribute name -> declared type, for event or object types."""
    return {
        kind.get("name"): {
            a.get("name"): a.get("type", "string")
            for a in _children(kind, "attributes", "attribute")
        }
        for kind in _children(root, f"{tag}s", tag)
    }


def _xml_name(path: Path, attribute: Any) -> str:
    name = attribute.get("name")
    if not name:
        raise InputError(f"{path} line {attribute.sourceline}: an <attribute> has no name.")
    return str(name)


def _xml_target(path: Path, link: Any) -> str:
    target = link.get("object-id")
    if not target:
        raise InputError(f"{path} line {link.sourceline}: a <relationship> has no object-id.")
    return str(target)


def _xml_value(path: Path, attribute: Any, kind: str) -> Any:
    text = attribute.text or ""
    convert = _XML_VALUES.get(kind, str)
    try:
        return convert(text.strip() if kind != "string" else text)
    except ValueError:
        raise InputError(
            f"{path} line {attribute.sourceline}: the {kind} attribute "
            f"{attribute.get('name')!r} has the value {text!r}."
        ) from None


# -- SQLite ------------------------------------------------------------------------------------

_SQLITE_TABLES = (
    "event",
    "object",
    "event_object",
    "object_object",
    "event_map_type",
    "object_map_type",
)


def _read_sqlite(path: Path) -> ObjectLog:
    try:
        connection = sqlite3.connect(f"{path.resolve().as_uri()}?mode=ro", uri=True)
    except sqlite3.Error as error:
        raise InputError(f"{path} is not an OCEL 2.0 SQLite database ({error}).") from None
    try:
        return _sqlite_log(path, connection)
    except sqlite3.DatabaseError as error:
        raise InputError(f"{path} is not a readable OCEL 2.0 SQLite database ({error}).") from None
    finally:
        connection.close()


def _sqlite_log(path: Path, connection: sqlite3.Connection) -> ObjectLog:
    present = {row[0] for row in connection.execute("SELECT name FROM sqlite_master")}
    for table in _SQLITE_TABLES:
        if table not in present:
            raise InputError(
                f"{path} is not an OCEL 2.0 SQLite database: it has no table {table!r}."
            )
    tables = _Tables(path)
    object_maps = dict(connection.execute("SELECT ocel_type, ocel_type_map FROM object_map_type"))
    for kind, object_id in connection.execute("SELECT ocel_type, ocel_id FROM object"):
        tables.object(f"the object {object_id!r} of table 'object'", object_id, kind)
    initial: dict[str, dict[str, Any]] = {}
    for mapped in object_maps.values():
        for number, row in enumerate(_rows(path, connection, f"object_{mapped}", present), 1):
            where = f"row {number} of table {'object_' + mapped!r}"
            object_id = row.pop("ocel_id", None)
            changed = row.pop("ocel_changed_field", None)
            time = row.pop("ocel_time", None)
            if changed:
                at = _time(path, where, time)
                tables.changes.append((str(object_id), at, changed, row.get(changed)))
            else:
                initial.setdefault(str(object_id), {}).update(row)
    for entry in tables.objects:
        entry.update({f"\0{k}": v for k, v in initial.get(entry["id"], {}).items()})
    events = {
        event_id: kind
        for event_id, kind in connection.execute("SELECT ocel_id, ocel_type FROM event")
    }
    event_maps = dict(connection.execute("SELECT ocel_type, ocel_type_map FROM event_map_type"))
    details: dict[str, dict[str, Any]] = {}
    for mapped in event_maps.values():
        for row in _rows(path, connection, f"event_{mapped}", present):
            details[str(row.pop("ocel_id", None))] = row
    for number, (event_id, kind) in enumerate(events.items(), start=1):
        where = f"row {number} of table 'event' ({event_id!r})"
        row = dict(details.get(str(event_id), {}))
        time = row.pop("ocel_time", None)
        row.pop("ocel:activity", None)  # pm4py's copy of the type
        tables.event(where, event_id, kind, time, row)
    query = "SELECT ocel_event_id, ocel_object_id, ocel_qualifier FROM event_object"
    tables.e2o += [(str(e), str(o), q) for e, o, q in connection.execute(query)]
    query = "SELECT ocel_source_id, ocel_target_id, ocel_qualifier FROM object_object"
    tables.o2o += [(str(s), str(t), q) for s, t, q in connection.execute(query)]
    return tables.finish()


def _rows(
    path: Path, connection: sqlite3.Connection, table: str, present: set[str]
) -> Iterable[dict[str, Any]]:
    if table not in present:
        raise InputError(f"{path}: the OCEL 2.0 SQLite database has no table {table!r}.")
    cursor = connection.execute(f'SELECT * FROM "{table.replace(chr(34), chr(34) * 2)}"')
    names = [column[0] for column in cursor.description]
    return (dict(zip(names, row, strict=True)) for row in cursor)
