"""Objects of an OCED-style CSV log: one column per object type, one table per type.

The events are a CSV log robotale reads as any other (:mod:`.readers`); a column of it holds
the objects of one type each event relates to (a cell may list several, comma-separated).
``DIR/<Type>.csv`` (the ``--objects`` folder) names the type and lists its objects: an ``id``
column and one column per attribute. The type's column in the events is the one named
``<Type>`` (or, failing that, the one whose name differs only in case, blanks, ``_`` or ``-``).
Objects an event names but its type's table does not list are objects without attributes.
"""

from __future__ import annotations

import io
from pathlib import Path

import pandas as pd

from robotale.errors import InputError
from robotale.eventlog import reading, schema
from robotale.eventlog.objects import (
    SEPARATOR,
    Objects,
    check_attribute_names,
    check_object_ids,
)


def read_object_tables(folder: Path, log: pd.DataFrame, source: Path) -> Objects:
    """The objects ``folder`` lists for the canonical ``log`` read from ``source``."""
    if not folder.is_dir():
        what = "is not a folder" if folder.exists() else "does not exist"
        raise InputError(f"The objects folder {folder} {what}.")
    files = sorted(p for p in folder.iterdir() if p.suffix.lower() == ".csv" and p.is_file())
    if not files:
        raise InputError(f"The objects folder {folder} holds no <Type>.csv file.")
    tables, links = [], []
    for file in files:
        column = _column_of(file, log, source)
        table = _object_table(file).assign(type=column)
        named = _named_objects(log, column)
        missing = sorted(set(named["object"]) - set(table["id"]))
        table = pd.concat([table, pd.DataFrame({"type": column, "id": missing})], ignore_index=True)
        tables.append(table)
        links.append(named)
    objects = pd.concat(tables, ignore_index=True)
    check_object_ids(folder, objects)
    objects = objects[["type", "id", *(c for c in objects.columns if c not in ("type", "id"))]]
    e2o = pd.concat(links, ignore_index=True).assign(qualifier=None)
    return Objects(objects=objects, e2o=e2o[["event", "object", "qualifier"]])


def _column_of(file: Path, log: pd.DataFrame, source: Path) -> str:
    kind = file.stem
    if kind in log.columns:
        return kind
    close = [c for c in log.columns if reading.normalised(c) == reading.normalised(kind)]
    if len(close) == 1:
        return str(close[0])
    raise InputError(
        f"{file} lists objects of the type {kind!r}, but {source} has no column {kind!r} "
        "naming each event's objects of that type."
    )


def _object_table(file: Path) -> pd.DataFrame:
    try:
        text = file.read_bytes().decode("utf-8-sig")
    except UnicodeDecodeError:
        raise InputError(f"{file} is not UTF-8 text; save it as UTF-8.") from None
    try:
        table = pd.read_csv(
            io.StringIO(text),
            dtype={"id": str},
            keep_default_na=False,
            na_values=sorted(reading.MISSING_MARKERS),
            index_col=False,
        )
    except (pd.errors.ParserError, pd.errors.EmptyDataError, ValueError) as error:
        reason = " ".join(str(error).split())
        raise InputError(f"{file} is not a readable CSV file: {reason}") from None
    if "id" not in table.columns:
        shown = ", ".join(repr(c) for c in table.columns[:10])
        raise InputError(f"{file} has no 'id' column naming its objects; its columns are {shown}.")
    empty = table["id"].isna()
    if empty.any():
        raise InputError(f"{file} line {int(empty.to_numpy().argmax()) + 2}: the id is empty.")
    table["id"] = table["id"].str.strip()
    check_attribute_names(file, [c for c in table.columns if c != "id"], f"{file.stem}")
    return table


def _named_objects(log: pd.DataFrame, column: str) -> pd.DataFrame:
    """``event`` (event id) and ``object`` for every object a cell of ``column`` names."""
    cells = log[column].dropna().astype(str).str.split(SEPARATOR).explode().str.strip()
    cells = cells[cells != ""]
    events = log[schema.EVENT_ID].astype(str).to_numpy()[cells.index.to_numpy()]
    return pd.DataFrame({"event": events, "object": cells.to_numpy()})
