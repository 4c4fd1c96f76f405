"""An event log as a Parquet dataset partitioned by run: one folder, one file per case.

The layout is Hive's, which pyarrow, pandas, DuckDB, Spark and Polars read as one table::

    agri.parquet/
        case=run_0001/part-0.parquet
        case=run_0002/part-0.parquet
        _robotale_dataset.json       the manifest: every part, its rows, the column types

The files hold the log's columns under their short CSV names (``time``, ``activity`` ...)
except ``case``, which the folder names. Every part has the same column types (those of the
canonical log: text as strings, ``time`` as UTC nanoseconds, numbers as doubles), so a
reader never has to reconcile them. Datasets written before times kept nanoseconds hold UTC
microseconds; they are read as they are.

Each part is written whole by whoever prepared its run (a Dask worker writes its own); the
process that asked writes the manifest last. Until then the folder holds
``_robotale_writing.json`` instead, so a dataset whose writing stopped half-way is never
taken for a whole one. Both names start with ``_``, which the readers above skip.
"""

from __future__ import annotations

import json
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any
from urllib.parse import quote

import numpy as np
import pandas as pd
import pyarrow as pa
import pyarrow.parquet as pq

from robotale.errors import InputError
from robotale.eventlog import schema
from robotale.storage import Place

MANIFEST = "_robotale_dataset.json"
WRITING = "_robotale_writing.json"
FORMAT = "robotale event log, partitioned by case"
PART = "part-0.parquet"
CASE_KEY = "case"

_TIME = pa.timestamp("ns", tz="UTC")
#: the time of datasets written when the log held microseconds (still read)
_TIME_US = pa.timestamp("us", tz="UTC")
#: the types of the canonical columns; other columns are numbers or text, as their values are
_KNOWN_TYPES: dict[str, pa.DataType] = {
    **{schema.CSV_NAMES[c]: pa.string() for c in schema.CSV_NAMES},
    "time": _TIME,
    **{name: pa.float64() for name in ("x", "y", "z", "battery", "source_index")},
}


@dataclass(frozen=True)
class PartWritten:
    """One case's part as it was written: its file inside the dataset, rows, column types."""

    case: str
    file: str
    rows: int
    types: tuple[tuple[str, str], ...]


def part_file(case: str) -> str:
    """The file of ``case`` inside the dataset (the value escaped as pyarrow's Hive
    partitioning unescapes it)."""
    return f"{CASE_KEY}={quote(case, safe='')}/{PART}"


def arrow_type(name: str, values: pd.Series) -> pa.DataType:
    """The Parquet type of a column: fixed for the canonical ones, else doubles for numbers
    (and for a column with no value at all, as a CSV reader takes it), booleans, or text."""
    if name in _KNOWN_TYPES:
        return _KNOWN_TYPES[name]
    if pd.api.types.is_bool_dtype(values):
        return pa.bool_()
    if pd.api.types.is_numeric_dtype(values) or values.isna().all():
        return pa.float64()
    return pa.string()


def part_table(log: pd.DataFrame) -> pa.Table:
    """The rows of one case as the part's table (short names, no ``case`` column)."""
    table = schema.to_csv_names(log).drop(columns=[CASE_KEY])
    arrays, fields = [], []
    for name in table.columns:
        kind = arrow_type(name, table[name])
        arrays.append(_array(table[name], kind))
        fields.append(pa.field(name, kind))
    return pa.Table.from_arrays(arrays, schema=pa.schema(fields))


def _array(values: pd.Series, kind: pa.DataType) -> pa.Array:
    if kind == _TIME:
        return pa.array(values.dt.tz_convert("UTC").dt.as_unit("ns"), type=_TIME)
    if kind == pa.string():
        present = values.notna().to_numpy()
        text = np.where(present, values.astype(str).to_numpy(object), None)
        return pa.array(text, type=pa.string())
    return pa.array(values.astype(kind.to_pandas_dtype()), type=kind, from_pandas=True)


def write_part(log: pd.DataFrame, dataset: Place) -> PartWritten:
    """Write the rows of one case (``log`` holds no other) into ``dataset``, whole."""
    cases = log[schema.CASE].astype(str).unique()
    if len(cases) != 1:
        raise ValueError(f"a part holds one case, not {len(cases)}")
    table = part_table(log)
    sink = pa.BufferOutputStream()
    pq.write_table(table, sink)
    file = part_file(str(cases[0]))
    dataset.child(*file.split("/")).write_whole(sink.getvalue().to_pybytes())
    types = tuple((field.name, str(field.type)) for field in table.schema)
    return PartWritten(str(cases[0]), file, len(table), types)


# -- the dataset as a whole ---------------------------------------------------------------------


def check_target(dataset: Place) -> None:
    """Refuse, before any run is read, a target that is a file or a folder of something
    else; a robotale dataset there is replaced."""
    if not dataset.exists():
        return
    if not dataset.is_dir():
        raise InputError(
            f"{dataset.text} is a file; a Parquet dataset is a folder: give a name that is "
            "free or an earlier dataset's."
        )
    ours = dataset.child(MANIFEST).exists() or dataset.child(WRITING).exists()
    if not ours and dataset.names():
        raise InputError(
            f"{dataset.text} is a folder that holds other files, not a robotale Parquet "
            "dataset: give a name that is free or an earlier dataset's."
        )


def begin(dataset: Place, source: str) -> None:
    """Mark ``dataset`` as being written, after removing an earlier dataset there (its
    manifest first, so that no reader takes a half-removed dataset for a whole one)."""
    check_target(dataset)
    if dataset.child(MANIFEST).exists():
        dataset.child(MANIFEST).remove()
    if dataset.exists():
        dataset.remove()
    dataset.fs.makedirs(dataset.path, exist_ok=True)
    dataset.child(WRITING).write_whole(json.dumps({"format": FORMAT, "source": source}) + "\n")


def finish(dataset: Place, parts: Sequence[PartWritten], source: str) -> dict[str, Any]:
    """Write the manifest of a dataset whose parts are all written; returns it."""
    types = column_types(parts)
    manifest = {
        "format": FORMAT,
        "version": 1,
        "source": source,
        "partitioning": "hive",
        "rows": sum(p.rows for p in parts),
        "columns": [{"name": name, "type": kind} for name, kind in types.items()],
        "parts": [{"case": p.case, "file": p.file, "rows": p.rows} for p in parts],
    }
    dataset.child(MANIFEST).write_whole(json.dumps(manifest, indent=2) + "\n")
    dataset.child(WRITING).remove()
    return manifest


def abandon(dataset: Place) -> None:
    """Remove a dataset whose writing failed (nothing half-written stays behind)."""
    if dataset.exists() and not dataset.child(MANIFEST).exists():
        dataset.remove()


def column_types(parts: Sequence[PartWritten]) -> dict[str, str]:
    """The columns of the whole dataset and their one type each, in the parts' order."""
    types: dict[str, str] = {CASE_KEY: "string"}
    for part in parts:
        for name, kind in part.types:
            known = types.setdefault(name, kind)
            if known != kind:
                raise InputError(
                    f"The column {name} holds {_kind_words(known)} in one run and "
                    f"{_kind_words(kind)} in {part.case}: a Parquet dataset needs one type "
                    "per column; prepare those runs into CSV instead."
                )
    return types


def _kind_words(kind: str) -> str:
    return {"double": "numbers", "string": "text", "bool": "booleans"}.get(kind, kind)


# -- reading ------------------------------------------------------------------------------------


def read_manifest(dataset: Place) -> Mapping[str, Any] | None:
    """The manifest of a robotale dataset; None for a folder robotale did not write."""
    manifest = dataset.child(MANIFEST)
    if not manifest.exists():
        if dataset.child(WRITING).exists():
            raise InputError(
                f"{dataset.text} is a Parquet dataset whose writing did not finish (it has "
                f"{WRITING} and no {MANIFEST}): prepare it again."
            )
        return None
    try:
        found: dict[str, Any] = json.loads(manifest.read_bytes())
        parts = found["parts"]
        columns = found["columns"]
        _ = [(p["file"], int(p["rows"])) for p in parts] + [(c["name"], c["type"]) for c in columns]
    except (ValueError, KeyError, TypeError):
        raise InputError(
            f"{manifest.text} is damaged (not the JSON robotale writes with parts, rows and "
            "columns): prepare the dataset again."
        ) from None
    return found


#: the types a manifest names, by the name pyarrow gives them
_TYPES = {str(kind): kind for kind in (pa.string(), pa.float64(), pa.bool_(), _TIME, _TIME_US)}


def arrow_schema(manifest: Mapping[str, Any], text: str) -> pa.Schema:
    """The columns a manifest declares; an unknown type is the manifest's damage."""
    unknown = [c["type"] for c in manifest["columns"] if c["type"] not in _TYPES]
    if unknown:
        raise InputError(
            f"{text}: its manifest names the column type {unknown[0]!r}, which robotale does "
            "not write: prepare the dataset again."
        )
    return pa.schema([pa.field(c["name"], _TYPES[c["type"]]) for c in manifest["columns"]])


def read_table(dataset: Place, manifest: Mapping[str, Any]) -> pa.Table:
    """Every part the manifest lists, in its order, checked against its row count, as one
    table with the ``case`` column first."""
    declared = arrow_schema(manifest, dataset.text)
    tables = []
    for part in manifest["parts"]:
        file = dataset.child(*str(part["file"]).split("/"))
        table = _read_part(file)
        if len(table) != int(part["rows"]):
            raise InputError(
                f"{file.text} holds {len(table)} rows where the manifest of {dataset.text} "
                f"records {part['rows']}: the dataset is damaged; prepare it again."
            )
        cases = pa.array([str(part["case"])] * len(table), type=pa.string())
        tables.append(_conformed(table.append_column(CASE_KEY, cases), declared, file.text))
    if not tables:
        return declared.empty_table()
    return pa.concat_tables(tables)


def _read_part(file: Place) -> pa.Table:
    if not file.exists():
        raise InputError(
            f"{file.text} is missing, though the manifest lists it: the dataset is damaged; "
            "prepare it again."
        )
    try:
        with file.fs.open(file.path, "rb") as handle:
            return pq.read_table(handle)
    except (pa.ArrowException, OSError) as error:
        reason = " ".join(str(error).split())[:200]
        raise InputError(f"{file.text} is not a readable Parquet file ({reason}).") from None


def _conformed(table: pa.Table, declared: pa.Schema, text: str) -> pa.Table:
    """``table`` with the declared columns in their order (a column a part lacks is empty)."""
    columns = []
    for field in declared:
        if field.name not in table.column_names:
            columns.append(pa.nulls(len(table), field.type))
            continue
        column = table.column(field.name)
        if column.type != field.type:
            raise InputError(
                f"{text}: its column {field.name} holds {column.type}, not the {field.type} "
                "the manifest declares: the dataset is damaged; prepare it again."
            )
        columns.append(column)
    return pa.Table.from_arrays(columns, schema=declared)
