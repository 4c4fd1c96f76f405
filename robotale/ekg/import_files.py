"""The tables of one log (:mod:`robotale.ekg.tables`) as the input of Neo4j's offline importer.

The files hold exactly the nodes, relationships and properties (with their Neo4j types) that
the online build writes through Cypher (:mod:`robotale.ekg.build`): events, entities and
classes, the log's ``Log`` node and its ``LogLock``, CORR, OBSERVED, DF, COMM, BEGINS and
DF_C. Each file has its header on its first line; nodes get integer ids in one id space
(events, then entities, classes, the Log node and the lock), which the importer does not store.

Values are written as the importer reads them: strings always quoted (an unquoted empty field
is a missing value, as ``None`` is online), floats in their shortest exact form, times with
nanoseconds, their offset and, where the log has one, their zone's name.
"""

from __future__ import annotations

from collections.abc import Iterable, Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pandas as pd

from robotale.ekg.load import timezone_name
from robotale.ekg.tables import ClassTables, GraphTables
from robotale.neo4j_server.importer import ImportFiles

#: rows formatted and written at a time: bounds the memory the text of a file takes
_CHUNK = 200_000
#: the separator of array values in a field (the importer's default)
ARRAY_DELIMITER = ";"


@dataclass(frozen=True)
class Column:
    """One property of a file: its header (``name:type``) and its fields as text."""

    header: str
    fields: pd.Series


def unsupported(tables: GraphTables, classes: Sequence[ClassTables]) -> str | None:
    """Why these tables cannot go through the importer unchanged (None: they can)."""
    events = tables.events
    for name in events.columns:
        if name != "timestamp" and _kind(events[name]) is None:
            return f"the column {name!r} holds values of several kinds or lists"
        if ":" in name:
            return f"the column name {name!r} has a colon, which the importer's header reads"
    for table in [tables.entities, tables.df, tables.comm, *(c.classes for c in classes)]:
        for name in table.columns:
            if _kind(table[name]) is None:
                return f"the values of {name!r} are of several kinds"
    return None


def write_import_files(
    folder: Path,
    tables: GraphTables,
    classes: Sequence[ClassTables],
    log: dict[str, object],
    lock: dict[str, object],
) -> ImportFiles:
    """Write the graph of ``tables`` and ``classes`` for the log whose ``Log`` node has the
    properties ``log`` (``name`` first) and whose write lock has ``lock``, into ``folder``."""
    name = str(log["name"])
    events, entities = tables.events, tables.entities
    entity_base = len(events)
    class_bases = list(np.cumsum([entity_base + len(entities), *(len(c.classes) for c in classes)]))
    log_id, lock_id = class_bases[-1], class_bases[-1] + 1
    nodes = [
        ("Event", _write(folder / "events.csv", _event_columns(events, name))),
        ("Entity", _write(folder / "entities.csv", _entity_columns(entities, name, entity_base))),
    ]
    for k, kind in enumerate(classes):
        columns = _class_columns(kind, name, int(class_bases[k]))
        nodes.append(("Class", _write(folder / f"classes{k}.csv", columns)))
    nodes.append(("Log", _write(folder / "log.csv", _single(log_id, log))))
    nodes.append(("LogLock", _write(folder / "lock.csv", _single(lock_id, lock))))
    corr = tables.corr
    df, comm = tables.df, tables.comm
    relationships = [
        ("CORR", _edges(folder / "corr.csv", corr["event"], corr["entity"] + entity_base)),
        ("DF", _edges(folder / "df.csv", df["source"], df["target"],
                      _properties(df, "entityType", "entityId"))),
        ("COMM", _edges(folder / "comm.csv", comm["source"], comm["target"],
                        _properties(comm, "msgId"))),
    ]  # fmt: skip
    for k, kind in enumerate(classes):
        base = int(class_bases[k])
        observed = pd.Series(kind.observed + base)
        events_at = pd.Series(np.arange(len(events)))
        relationships.append(("OBSERVED", _edges(folder / f"observed{k}.csv", events_at, observed)))
        entries = kind.entries
        begins = _properties(entries, "cases")
        relationships.append(
            ("BEGINS", _edges(folder / f"begins{k}.csv", entries["entity"] + entity_base,
                              entries["class"] + base, begins))
        )  # fmt: skip
        df_c = kind.df_c
        measures = _properties(df_c, "entityType", "count")
        # the online build stores a mean or median of no interval as NaN, not as no value
        measures += [_double(df_c[c], c, keep_nan=True) for c in ("meanSeconds", "medianSeconds")]
        relationships.append(
            ("DF_C", _edges(folder / f"df_c{k}.csv", df_c["source"] + base,
                            df_c["target"] + base, measures))
        )  # fmt: skip
    node_count = int(lock_id) + 1
    edge_count = len(corr) + len(tables.df) + len(tables.comm)
    edge_count += sum(len(events) + len(c.entries) + len(c.df_c) for c in classes)
    multiline = _has_line_breaks(tables, classes)
    return ImportFiles(nodes, relationships, multiline, (node_count, edge_count))


# -- the columns of each file ----------------------------------------------------------------


def _event_columns(events: pd.DataFrame, log: str) -> list[Column]:
    size = len(events)
    columns = [
        _ids(pd.Series(np.arange(size))),
        _constant("log", log, size),
        _typed(events["id"], "id"),
        Column("order:long", pd.Series(np.arange(size)).astype(str)),
        _times(events["timestamp"], "timestamp"),
    ]
    others = [name for name in events.columns if name not in ("id", "timestamp")]
    return columns + [_typed(events[name], name) for name in others]


def _entity_columns(entities: pd.DataFrame, log: str, base: int) -> list[Column]:
    return [
        _ids(pd.Series(np.arange(len(entities)) + base)),
        _constant("log", log, len(entities)),
        _typed(entities["type"], "type"),
        _typed(entities["id"], "id"),
    ]


def _class_columns(kind: ClassTables, log: str, base: int) -> list[Column]:
    table = kind.classes
    size = len(table)
    columns = [
        _ids(pd.Series(np.arange(size) + base)),
        _constant("log", log, size),
        _constant("type", kind.type, size),
        _typed(table["id"], "id"),
        Column("key:string[]", pd.Series([_quote_array(kind.key)] * size, dtype=object)),
    ]
    return columns + [_typed(table[name], name) for name in kind.key]


def _single(node: int, properties: dict[str, object]) -> list[Column]:
    """The columns of a file of one node with ``properties`` (texts, integers, lists of
    texts, or :class:`Instant`)."""
    columns = [_ids(pd.Series([node]))]
    for name, value in properties.items():
        if isinstance(value, Instant):
            columns.append(Column(f"{name}:datetime", pd.Series([value.text])))
        elif isinstance(value, bool | int):
            columns.append(Column(f"{name}:long", pd.Series([str(int(value))])))
        elif isinstance(value, list | tuple):
            columns.append(Column(f"{name}:string[]", pd.Series([_quote_array(value)])))
        else:
            columns.append(Column(f"{name}:string", pd.Series([_quote(str(value))])))
    return columns


@dataclass(frozen=True)
class Instant:
    """A datetime property of a single node, as the importer reads it (ISO 8601)."""

    text: str


def _properties(table: pd.DataFrame, *names: str) -> list[Column]:
    return [_typed(table[name], name) for name in names]


# -- values as the importer reads them ---------------------------------------------------------


#: the importer's type of a column of each dtype, in the order neo4j_values tests them
_KINDS = (
    (pd.api.types.is_bool_dtype, "boolean"),
    (pd.api.types.is_integer_dtype, "long"),
    (pd.api.types.is_float_dtype, "double"),
)


def _kind(column: pd.Series) -> str | None:
    """The importer's type of ``column`` as :func:`robotale.ekg.load.neo4j_values` stores it
    (None: it has none, e.g. texts mixed with numbers; a time column other than the
    timestamp, which :func:`_times` writes)."""
    for test, kind in _KINDS:
        if test(column):
            return kind
    if pd.api.types.is_datetime64_any_dtype(column):
        return None
    if column.isna().all() or pd.api.types.infer_dtype(column, skipna=True) == "string":
        return "string"
    return None


def _typed(column: pd.Series, name: str) -> Column:
    kind = _kind(column)
    if kind == "double":
        return _double(column, name, keep_nan=False)
    if kind == "boolean":
        text = column.map({True: "true", False: "false"})
        return Column(f"{name}:boolean", text.astype(object).where(column.notna(), ""))
    if kind == "long":
        present = column.notna()
        text = column.astype(object).where(present, 0).astype("int64").astype(str)
        return Column(f"{name}:long", text.where(present, ""))
    values = column.astype(object)
    present = values.notna()
    text = '"' + values.where(present, "").astype(str).str.replace('"', '""', regex=False) + '"'
    return Column(f"{name}:string", text.where(present, ""))


def _double(column: pd.Series, name: str, keep_nan: bool) -> Column:
    values = column.to_numpy(float)
    text = pd.Series(values.astype(str)).str.replace("inf", "Infinity", regex=False)
    text = text.str.replace("nan", "NaN", regex=False)
    if not keep_nan:  # online, a missing float is no property
        text = text.where(~np.isnan(values), "")
    return Column(f"{name}:double", text)


def _times(times: pd.Series, name: str) -> Column:
    """Times in the zone the online build shows them in (:func:`timezone_name`)."""
    zone = timezone_name(times)
    named = "/" in zone or zone == "UTC"
    shown = times.dt.tz_convert(zone) if named else times
    local = shown.dt.tz_localize(None)
    utc = times.dt.tz_convert("UTC").dt.tz_localize(None)
    offsets = ((local - utc) // pd.Timedelta(minutes=1)).astype("int64")
    suffixes = offsets.map({m: _offset(m) for m in offsets.unique().tolist()})
    if named:
        suffixes = suffixes + f"[{zone}]"
    text = pd.Series(np.datetime_as_string(local.to_numpy("datetime64[ns]"), unit="ns"))
    return Column(f"{name}:datetime", text + suffixes.to_numpy())


def _offset(minutes: int) -> str:
    sign = "-" if minutes < 0 else "+"
    return f"{sign}{abs(minutes) // 60:02d}:{abs(minutes) % 60:02d}"


def instant(moment: pd.Timestamp) -> Instant:
    """``moment`` (with a zone) as a datetime property of a single node."""
    return Instant(moment.isoformat())


def _ids(values: pd.Series) -> Column:
    return Column(":ID", values.astype(str))


def _constant(name: str, value: str, size: int) -> Column:
    return Column(f"{name}:string", pd.Series([_quote(value)] * size, dtype=object))


def _quote(text: str) -> str:
    return '"' + text.replace('"', '""') + '"'


def _quote_array(values: Iterable[object]) -> str:
    return _quote(ARRAY_DELIMITER.join(str(v) for v in values))


def _has_line_breaks(tables: GraphTables, classes: Sequence[ClassTables]) -> bool:
    tables_with_text = [tables.events, tables.entities, tables.df, tables.comm]
    tables_with_text += [c.classes for c in classes]
    for table in tables_with_text:
        for name in table.columns:
            column = table[name]
            if (
                _kind(column) == "string"
                and column.astype("string").str.contains(r"[\r\n]", regex=True, na=False).any()
            ):
                return True
    return False


# -- the files ---------------------------------------------------------------------------------


def _edges(
    path: Path, sources: pd.Series, targets: pd.Series, properties: Sequence[Column] = ()
) -> Path:
    columns = [
        Column(":START_ID", pd.Series(np.asarray(sources)).astype(str)),
        Column(":END_ID", pd.Series(np.asarray(targets)).astype(str)),
        *properties,
    ]
    return _write(path, columns)


def _write(path: Path, columns: Sequence[Column]) -> Path:
    size = len(columns[0].fields)
    with path.open("w", encoding="utf-8", newline="") as out:
        out.write(",".join(column.header for column in columns) + "\n")
        for start in range(0, size, _CHUNK):
            parts = [
                pd.Series(column.fields.to_numpy()[start : start + _CHUNK], dtype=object)
                for column in columns
            ]
            lines = parts[0].str.cat(parts[1:], sep=",") if len(parts) > 1 else parts[0]
            out.write("\n".join(lines.tolist()))
            out.write("\n")
    return path
