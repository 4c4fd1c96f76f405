"""A columnar copy of every stored log, kept beside the graph: :func:`stored_table`.

Every analysis of a stored log (perspectives, discovery, findings, the dashboard's pages) needs
the log's whole event table; reading it back event by event from Neo4j costs more than the
analysis itself. So the event table a log was built from is also written as a Parquet file
(by :func:`~robotale.ekg.build.build_ekg`, under the log's write lock)
under the robotale home, ``columnar/<log>/<build>/events.parquet``, with the reader's column
types (pandas string dtype, timestamps in their zone and unit, categoricals), and read from
there while it belongs to the log's current build. The graph stays the source of truth: a
build is the Log node's creation time, run and last append, so a rebuild (here or on another
machine), an append, a deleted or damaged file, or a log stored by another tool makes the
copy be read again from the graph, in columns, and saved. The column types travel on the Log
node (an Arrow schema), so a copy read back from the graph has the reader's types too.

Results computed from one build (the dashboard's perspectives and findings) live in the same
build folder, ``results/``, so a new build leaves them behind with the old copy.
"""

from __future__ import annotations

import contextlib
import datetime as dt
import hashlib
import json
import logging
import shutil
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd
import pyarrow as pa
import pyarrow.parquet as pq
from neo4j import Driver

from robotale.config import robotale_home
from robotale.ekg.connection import database, read_rows
from robotale.ekg.logs import log_build_row
from robotale.ekg.tables import EVENT_PROPERTIES, property_name
from robotale.errors import InputError, RobotaleError
from robotale.eventlog import schema
from robotale.files import atomic_file
from robotale.queries import cypher

#: the folder of the copies under the robotale home
FOLDER = "columnar"
EVENTS = "events.parquet"
RESULTS = "results"
#: the Parquet metadata key naming the build a copy belongs to
BUILD_KEY = b"robotale.build"
COMPLETE = "complete"

_log = logging.getLogger(__name__)


@dataclass(frozen=True)
class Build:
    """One build of a stored log, as its Log node records it."""

    name: str
    status: str
    created: str
    run: str
    appended: str  # when runs were last appended ("None" if never): the log changed
    properties: list[str]
    columns: pa.Schema | None  # the event table's column types, if recorded

    @property
    def key(self) -> str:
        """A short name of this build, the same on every machine that reads the graph."""
        return hashlib.sha256(f"{self.created}|{self.run}|{self.appended}".encode()).hexdigest()[
            :16
        ]

    @property
    def complete(self) -> bool:
        return self.status == COMPLETE


def log_build(driver: Driver, name: str, hint: str | None = None) -> Build:
    """The current build of the stored log ``name`` (a :class:`LogNotFound` if none)."""
    return build_of(name, log_build_row(driver, name, hint))


def build_of(name: str, row: dict[str, Any]) -> Build:
    """The build of the log ``name`` that ``row`` (a row of ``cypher/ekg_log_build``) tells:
    for a writer that read the row in a transaction of its own, with its lock."""
    return Build(
        name=name,
        status=str(row["status"]),
        created=str(row["created"]),
        run=str(row["run"]),
        appended=str(row["appended"]),
        properties=list(row["properties"] or []),
        columns=_schema(row["columns"]),
    )


def log_folder(name: str) -> Path:
    """The folder of every copy of the log ``name`` (log names may hold any character, so the
    folder is named by a digest of the name)."""
    digest = hashlib.sha256(name.encode("utf-8")).hexdigest()[:32]
    return robotale_home() / FOLDER / digest


def build_folder(build: Build) -> Path:
    return log_folder(build.name) / build.key


def results_folder(build: Build) -> Path:
    """Where results computed from ``build`` are kept (created if missing)."""
    folder = build_folder(build) / RESULTS
    folder.mkdir(parents=True, exist_ok=True)
    return folder


def store_copy(driver: Driver, name: str, log: pd.DataFrame) -> Path | None:
    """Keep ``log``, the event table the log ``name`` was just built from, as its columnar
    copy and record its column types on the Log node. Returns the copy's path, or None when it
    could not be kept (the log is stored all the same; its first analysis reads the graph)."""
    try:
        build = log_build(driver, name)
        table = _arrow_table(log)
        driver.execute_query(
            cypher("ekg_log_set_columns"),
            log=name,
            run=build.run,
            columns=_recorded(table.schema),
            database_=database(),
        )
        return _save(build, table)
    except (OSError, RobotaleError, pa.ArrowException) as error:
        _log.warning("The columnar copy of %r was not kept (%s).", name, error)
        return None


def widened_schema(columns: pa.Schema, added: pd.DataFrame) -> bytes:
    """The column types ``columns`` of a log with the columns of ``added`` after them, as the
    Log node records them: appended runs that bring a column the log did not have."""
    more = _arrow_table(added).schema
    recorded = (columns.metadata or {}).get(b"pandas")
    fields = [*columns, *more]
    if recorded is None:  # no pandas description to extend: Arrow's own types restore it
        serialized: bytes = pa.schema(fields).serialize().to_pybytes()
        return serialized
    described = json.loads(recorded)
    described["columns"] += json.loads(more.metadata[b"pandas"])["columns"]
    return _recorded(pa.schema(fields, metadata={b"pandas": json.dumps(described).encode()}))


def _recorded(columns: pa.Schema) -> bytes:
    """``columns`` as the Log node records them: the fields and pandas' description only."""
    serialized: bytes = (
        columns.remove_metadata()
        .with_metadata({b"pandas": columns.metadata[b"pandas"]})
        .serialize()
        .to_pybytes()
    )
    return serialized


def stored_table(
    driver: Driver, name: str, hint: str | None = None, build: Build | None = None
) -> pd.DataFrame:
    """The events of the stored log ``name`` as a canonical event log: its columnar copy when
    it belongs to the log's current build, else read from the graph (and kept, if the log is
    complete). ``build``: the current build when the caller has read it already."""
    if build is None:
        build = log_build(driver, name, hint)
    if not build.complete:  # still being written, or failed: the graph is all there is
        return _graph_table(driver, build).to_pandas()
    path = build_folder(build) / EVENTS
    copy = _read_copy(path, build)
    if copy is not None:
        return copy
    table = _graph_table(driver, build)
    with contextlib.suppress(OSError, InputError):  # a read-only home still answers
        _save(build, table)
    return table.to_pandas()


def delete_copies(name: str) -> None:
    """Remove every copy of the log ``name`` and the results computed from them."""
    shutil.rmtree(log_folder(name), ignore_errors=True)


def _read_copy(path: Path, build: Build) -> pd.DataFrame | None:
    """The copy at ``path`` if it is there, whole and of ``build``; None otherwise."""
    try:
        table = pq.read_table(path)
    except FileNotFoundError:
        return None
    except (OSError, pa.ArrowException) as error:  # damaged: read again from the graph
        _log.warning("The columnar copy %s is damaged (%s); reading the graph again.", path, error)
        return None
    if (table.schema.metadata or {}).get(BUILD_KEY) != build.key.encode():
        return None
    return table.to_pandas()


def _save(build: Build, table: pa.Table) -> Path:
    """Write ``table`` as the copy of ``build`` whole, then drop the copies of other builds."""
    folder = build_folder(build)
    folder.mkdir(parents=True, exist_ok=True)
    path = folder / EVENTS
    metadata = dict(table.schema.metadata or {}) | {BUILD_KEY: build.key.encode()}
    with atomic_file(path, "wb") as file:
        pq.write_table(table.replace_schema_metadata(metadata), file)
    for other in log_folder(build.name).iterdir():
        if other.name != build.key and other.is_dir():
            shutil.rmtree(other, ignore_errors=True)
    return path


def _arrow_table(log: pd.DataFrame) -> pa.Table:
    """``log`` as an Arrow table whose pandas metadata restores the reader's column types.

    A column of mixed Python values (an XES attribute that is a number in one event and text in
    another) has no Arrow type; it is kept as text, as the graph keeps it.
    """
    try:
        return pa.Table.from_pandas(log, preserve_index=False)
    except (pa.ArrowInvalid, pa.ArrowTypeError, pa.ArrowNotImplementedError):
        mixed = {c: log[c].astype("string") for c in log.columns if log[c].dtype == object}
        return pa.Table.from_pandas(log.assign(**mixed), preserve_index=False)


def _schema(data: Any) -> pa.Schema | None:
    if not data:
        return None
    try:
        return pa.ipc.read_schema(pa.py_buffer(bytes(data)))
    except (pa.ArrowException, TypeError):  # written by another version: infer the types
        return None


# -- reading the graph in columns -------------------------------------------------------------


def _graph_table(driver: Driver, build: Build) -> pa.Table:
    """The log's events read from the graph as an Arrow table: with the recorded column types,
    or with types inferred from the values when none were recorded."""
    if build.columns is not None:
        keys = [property_name(f.name) for f in build.columns if f.name != schema.TIMESTAMP]
    else:
        keys = [p for p in build.properties if p != "timestamp"]
    values, nanos, zone = _graph_columns(driver, build.name, keys)
    if build.columns is not None:
        return _typed_table(build.columns, values, nanos)
    return _inferred_table(build.properties, values, nanos, zone)


def _graph_columns(
    driver: Driver, name: str, keys: list[str]
) -> tuple[dict[str, list[Any]], np.ndarray, str]:
    """The properties ``keys`` of every event in log order, the times in nanoseconds since the
    epoch, and the zone the times were given in."""
    records = read_rows(driver, cypher("ekg_event_columns"), log=name, keys=keys)
    values: dict[str, list[Any]] = {key: [] for key in keys}
    seconds: list[int] = []
    nanos: list[int] = []
    for record in records:
        for key, column in zip(keys, record["columns"], strict=True):
            values[key].extend(column)
        seconds.extend(record["seconds"])
        nanos.extend(record["nanos"])
    times = np.asarray(seconds, dtype="int64") * 10**9 + np.asarray(nanos, dtype="int64")
    return values, times, str(records[0]["zone"]) if records else "UTC"


def _typed_table(columns: pa.Schema, values: dict[str, list[Any]], nanos: np.ndarray) -> pa.Table:
    arrays = []
    for field in columns:
        if field.name == schema.TIMESTAMP:
            arrays.append(_times(nanos, field.type))
        else:
            arrays.append(_array(values[property_name(field.name)], field.type))
    return pa.Table.from_arrays(arrays, schema=columns)


def _times(nanos: np.ndarray, kind: pa.DataType) -> pa.Array:
    zone = getattr(kind, "tz", None) or "UTC"
    return pa.array(nanos, pa.timestamp("ns", tz=zone)).cast(kind, safe=False)


def _array(values: list[Any], kind: pa.DataType) -> pa.Array:
    """``values`` as an array of ``kind``; a dictionary (categorical) column is encoded from
    its values."""
    if pa.types.is_dictionary(kind):
        encoded = pa.array(values, kind.value_type).dictionary_encode()
        return encoded.cast(kind)
    try:
        return pa.array(values, kind)
    except (pa.ArrowInvalid, pa.ArrowTypeError):  # e.g. numbers in a text column
        return pa.array([None if v is None else str(v) for v in values]).cast(kind)


def _inferred_table(
    properties: list[str], values: dict[str, list[Any]], nanos: np.ndarray, zone: str
) -> pa.Table:
    """The events with the types their values suggest: text as pandas strings, numbers as
    floats (integers where none is missing), the times in microseconds where that loses
    nothing, shown in their zone."""
    frame = pd.DataFrame(
        {property_name_back(k): _inferred(v) for k, v in values.items() if k != "log"}
    )
    unit = "us" if len(nanos) and not (nanos % 1000).any() else "ns"
    times = pd.Series(pd.to_datetime(nanos, unit="ns", utc=True).as_unit(unit))
    position = properties.index("timestamp") if "timestamp" in properties else 0
    frame.insert(position, schema.TIMESTAMP, times.dt.tz_convert(_zone(zone)))
    return pa.Table.from_pandas(frame, preserve_index=False)


def _inferred(values: list[Any]) -> pd.Series:
    present = [v for v in values if v is not None]
    if present and all(isinstance(v, bool) for v in present):
        return pd.Series(values, dtype="boolean")
    if present and all(isinstance(v, int | float) and not isinstance(v, bool) for v in present):
        whole = len(present) == len(values) and all(isinstance(v, int) for v in present)
        return pd.Series(values, dtype="int64" if whole else "float64")
    if all(isinstance(v, str) for v in present):
        return pd.Series(values, dtype="string")
    return pd.Series([None if v is None else str(v) for v in values], dtype="string")


def property_name_back(prop: str) -> str:
    """The canonical column an Event property comes from (``activity`` -> ``concept:name``)."""
    back = {p: c for c, p in EVENT_PROPERTIES.items()}
    back |= {short: c for c, short in schema.CSV_NAMES.items() if short not in back}
    return back.get(prop, prop)


def _zone(name: str) -> dt.tzinfo | str:
    """A zone Neo4j reports (``Europe/Rome``, ``UTC``, ``+01:00``, ``Z``) for pandas."""
    if name in ("Z", "UTC", "+00:00"):
        return "UTC"
    if name[:1] in "+-" and ":" in name:
        hours, minutes = name[1:].split(":")
        offset = dt.timedelta(hours=int(hours), minutes=int(minutes))
        return dt.timezone(-offset if name[0] == "-" else offset)
    return name
