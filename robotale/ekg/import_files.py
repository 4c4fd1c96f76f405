"""The tables of one log (:mod:`robotale.ekg.tables`) as the input of Neo4j's offline importer.

The files hold exactly the nodes, relationships and properties (with their Neo4j types) that
the online build writes through Cypher (:mod:`robotale.ekg.build`): events, entities and
classes, the log's ``Log`` node and its ``LogLock``, CORR, OBSERVED, DF, COMM, BEGINS and
DF_C. Each file has its header on its first line; nodes get the ids 0, 1, 2 ... in one id space
(events, then entities, classes, the Log node and the lock), which the importer takes as the
nodes' own ids (none is stored as a property).

Values are written as the importer reads them: strings always quoted (an unquoted empty field
is a missing value, as ``None`` is online), floats in a form that reads back exactly, times with
nanoseconds, their offset and, where the log has one, their zone's name.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pandas as pd
import pyarrow as pa
import pyarrow.compute as pc
from pyarrow import csv

from robotale.ekg.load import timezone_name
from robotale.ekg.tables import ClassTables, GraphTables
from robotale.neo4j_server.importer import ImportFiles

#: rows the writer formats at a time: bounds the memory the text of a file takes
_CHUNK = 200_000
#: the separator of array values in a field (the importer's default)
ARRAY_DELIMITER = ";"


@dataclass(frozen=True)
class Column:
    """One property of a file: its header (``name:type``) and its values, which the writer
    formats (texts quoted, a missing value as an empty field)."""

    header: str
    fields: pa.Array


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
    expected = (node_count, edge_count)
    return ImportFiles(nodes, relationships, multiline, expected, dense_ids=True)


# -- the columns of each file ----------------------------------------------------------------


def _event_columns(events: pd.DataFrame, log: str) -> list[Column]:
    size = len(events)
    columns = [
        _ids(np.arange(size)),
        _constant("log", log, size),
        _typed(events["id"], "id"),
        Column("order:long", pa.array(np.arange(size, dtype=np.int64))),
        _times(events["timestamp"], "timestamp"),
    ]
    others = [name for name in events.columns if name not in ("id", "timestamp")]
    return columns + [_typed(events[name], name) for name in others]


def _entity_columns(entities: pd.DataFrame, log: str, base: int) -> list[Column]:
    return [
        _ids(np.arange(len(entities)) + base),
        _constant("log", log, len(entities)),
        _typed(entities["type"], "type"),
        _typed(entities["id"], "id"),
    ]


def _class_columns(kind: ClassTables, log: str, base: int) -> list[Column]:
    table = kind.classes
    size = len(table)
    columns = [
        _ids(np.arange(size) + base),
        _constant("log", log, size),
        _constant("type", kind.type, size),
        _typed(table["id"], "id"),
        _constant("key", ARRAY_DELIMITER.join(kind.key), size, "string[]"),
    ]
    return columns + [_typed(table[name], name) for name in kind.key]


def _single(node: int, properties: dict[str, object]) -> list[Column]:
    """The columns of a file of one node with ``properties`` (texts, integers, lists of
    texts, or :class:`Instant`)."""
    columns = [_ids(np.array([node]))]
    for name, value in properties.items():
        if isinstance(value, Instant):
            columns.append(_constant(name, value.text, 1, "datetime"))
        elif isinstance(value, bool | int):
            columns.append(Column(f"{name}:long", pa.array([int(value)], pa.int64())))
        elif isinstance(value, list | tuple):
            text = ARRAY_DELIMITER.join(str(v) for v in value)
            columns.append(_constant(name, text, 1, "string[]"))
        else:
            columns.append(_constant(name, str(value), 1))
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
#: the Arrow type each kind is written from (the writer quotes texts, not numbers)
_ARROW = {"boolean": pa.bool_(), "long": pa.int64(), "string": pa.large_string()}


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
    assert kind is not None, "unsupported() refused the column"
    return Column(f"{name}:{kind}", _arrow(column, _ARROW[kind]))


def _arrow(column: pd.Series, kind: pa.DataType) -> pa.Array | pa.ChunkedArray:
    """``column`` as Arrow values of ``kind``, a missing value (None, NaN, NA) as null."""
    return pa.array(column, from_pandas=True).cast(kind)


def _double(column: pd.Series, name: str, keep_nan: bool) -> Column:
    values = column.to_numpy(float)
    infinite = np.isinf(values)
    if not infinite.any() and not (keep_nan and np.isnan(values).any()):
        # online, a missing float is no property: NaN becomes an empty field
        return Column(f"{name}:double", pa.array(values, from_pandas=True))
    # the writer spells these "inf" and "nan"; the importer reads Java's spelling
    text = pd.Series(values.astype(str)).str.replace("inf", "Infinity", regex=False)
    text = text.str.replace("nan", "NaN", regex=False)
    if not keep_nan:
        text = text.where(~np.isnan(values), None)
    return Column(f"{name}:double", pa.array(text, pa.large_string(), from_pandas=True))


def _times(times: pd.Series, name: str) -> Column:
    """Times in the zone the online build shows them in (:func:`timezone_name`)."""
    zone = timezone_name(times)
    named = "/" in zone or zone == "UTC"
    shown = times.dt.tz_convert(zone) if named else times
    local = shown.dt.tz_localize(None)
    utc = times.dt.tz_convert("UTC").dt.tz_localize(None)
    offsets = ((local - utc) // pd.Timedelta(minutes=1)).to_numpy("int64")
    # few offsets (a zone's standard and summer time): each suffix written once
    unique, at = np.unique(offsets, return_inverse=True)
    suffixes = [_offset(int(m)) + (f"[{zone}]" if named else "") for m in unique]
    suffix = pa.array(suffixes, pa.large_string()).take(pa.array(at.astype(np.int64)))
    text = pa.array(np.datetime_as_string(local.to_numpy("datetime64[ns]"), unit="ns"))
    joined = pc.binary_join_element_wise(
        text.cast(pa.large_string()), suffix, pa.scalar("", pa.large_string())
    )
    return Column(f"{name}:datetime", joined)


def _offset(minutes: int) -> str:
    sign = "-" if minutes < 0 else "+"
    return f"{sign}{abs(minutes) // 60:02d}:{abs(minutes) % 60:02d}"


def instant(moment: pd.Timestamp) -> Instant:
    """``moment`` (with a zone) as a datetime property of a single node."""
    return Instant(moment.isoformat())


def _ids(values: np.ndarray) -> Column:
    return Column(":ID", pa.array(np.asarray(values, dtype=np.int64)))


def _constant(name: str, value: str, size: int, kind: str = "string") -> Column:
    return Column(f"{name}:{kind}", pa.repeat(pa.scalar(value, pa.large_string()), size))


def _has_line_breaks(tables: GraphTables, classes: Sequence[ClassTables]) -> bool:
    tables_with_text = [tables.events, tables.entities, tables.df, tables.comm]
    tables_with_text += [c.classes for c in classes]
    for table in tables_with_text:
        for name in table.columns:
            column = table[name]
            if (
                _kind(column) == "string"
                and pc.any(
                    pc.match_substring_regex(_arrow(column, pa.large_string()), r"[\r\n]")
                ).as_py()
            ):
                return True
    return False


# -- the files ---------------------------------------------------------------------------------


def _edges(
    path: Path, sources: pd.Series, targets: pd.Series, properties: Sequence[Column] = ()
) -> Path:
    columns = [
        Column(":START_ID", pa.array(np.asarray(sources, dtype=np.int64))),
        Column(":END_ID", pa.array(np.asarray(targets, dtype=np.int64))),
        *properties,
    ]
    return _write(path, columns)


def _write(path: Path, columns: Sequence[Column]) -> Path:
    """The header line, then Arrow's CSV writer: texts always quoted (an empty text is ``""``,
    a missing value an empty field, as the importer reads them), numbers as they are."""
    names = [f"c{k}" for k in range(len(columns))]
    table = pa.table([column.fields for column in columns], names=names)
    options = csv.WriteOptions(include_header=False, quoting_style="needed", batch_size=_CHUNK)
    with path.open("wb") as out:
        out.write((",".join(column.header for column in columns) + "\n").encode())
        csv.write_csv(table, out, options)
    return path
