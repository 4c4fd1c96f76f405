"""Read an event log from CSV, XES or Parquet into the canonical DataFrame of :mod:`.schema`.

How a log is read (which column is the case, the robot, its type, the lifecycle, which cells
mean "missing", which rows are samples) is decided in :mod:`.reading`, which also describes the
decisions: :func:`read_log_with_reading` returns that :class:`~.reading.Reading` next to the
log. Columns are recognised by their usual names (see :data:`.reading.SYNONYMS`) or mapped
explicitly with ``mapping={"Zeit": "time"}`` (the command line's ``--map Zeit=time``). Without a
case column the whole log is one case (``"1"``), unless ``case=`` names the column that tells
cases apart or ``case_gap=`` starts a new case after every pause that long. In XES the trace's
name is the case. Parquet is a file or a dataset folder: robotale's own, partitioned by case
(:mod:`.dataset`), or any Hive-partitioned folder of Parquet files; its rows count from 1 where
a sentence names a line. Rows keep their order in the file, which breaks ties between equal
timestamps later on.

Every problem is one :class:`~robotale.errors.InputError` naming the file and, where there is
one, the line.
"""

from __future__ import annotations

import csv
import dataclasses
import io
import warnings
from collections.abc import Callable, Iterator, Mapping, Sequence
from contextlib import suppress
from pathlib import Path
from typing import TypeAlias

import numpy as np
import pandas as pd
import pyarrow as pa
import pyarrow.parquet as pq
from lxml import etree

from robotale.errors import InputError
from robotale.eventlog import dataset, ocel, reading, schema
from robotale.eventlog.logkinds import OCEL, PARQUET, XES, kind_of
from robotale.eventlog.objects import Objects, entity_cells, entity_columns
from robotale.eventlog.oced import read_object_tables
from robotale.eventlog.reading import SYNONYMS, TEXT_COLUMNS, Reading, column_mapping, listing
from robotale.storage import place

SINGLE_CASE = "1"
#: a duration such as ``pd.Timedelta("1h")`` or the text ``"1h"``
Gap: TypeAlias = pd.Timedelta | str | None


def parse_mapping(items: Sequence[str]) -> dict[str, str]:
    """``--map`` options (``["Zeit=time", ...]``) as ``{"Zeit": "time"}``."""
    mapping = {}
    for item in items:
        column, sep, field = item.partition("=")
        if not sep or not column.strip() or not field.strip():
            raise InputError(f"--map {item!r} is not COLUMN=FIELD (e.g. --map Zeit=time).")
        mapping[column.strip()] = field.strip()
    return mapping


def read_log(
    path: str | Path,
    mapping: Mapping[str, str] | None = None,
    case: str | None = None,
    case_gap: Gap = None,
) -> pd.DataFrame:
    """Read a ``.csv``, ``.xes`` or Parquet event log (chosen by the file's extension; a
    Parquet dataset is a folder)."""
    return read_log_with_reading(path, mapping, case, case_gap)[0]


def read_log_with_reading(
    path: str | Path,
    mapping: Mapping[str, str] | None = None,
    case: str | None = None,
    case_gap: Gap = None,
) -> tuple[pd.DataFrame, Reading]:
    """The log and how it was read.

    The reading travels next to the DataFrame, not in ``DataFrame.attrs``: pandas copies
    ``attrs`` into some derived frames and not others, so a reading there would silently
    follow a filtered or merged log it no longer describes.
    """
    return read_with_objects(path, mapping, case, case_gap)[:2]


def read_with_objects(
    path: str | Path,
    mapping: Mapping[str, str] | None = None,
    case: str | None = None,
    case_gap: Gap = None,
    objects: str | Path | None = None,
) -> tuple[pd.DataFrame, Reading, Objects | None]:
    """The log, how it was read, and its objects where it is object-centric: an OCEL 2.0
    file (``.jsonocel``/``.json``, ``.xmlocel``/``.xml``, ``.sqlite``/``.db``), or a CSV log
    whose ``objects`` folder holds one ``<Type>.csv`` per object type (:mod:`.oced`).

    What kind of log a path is, :func:`~robotale.eventlog.logkinds.kind_of` decides.
    """
    path = Path(path)
    kind = kind_of(path)
    if kind is OCEL:
        if objects is not None:
            raise InputError(
                f"{path} is an OCEL 2.0 log, which lists its objects itself: --objects "
                "belongs to a CSV log."
            )
        return _read_ocel(path, mapping, case, case_gap)
    if kind is XES:
        log, found = _read_xes(path, mapping, case, case_gap)
    elif kind is PARQUET:
        log, found = _read_parquet(path, mapping, case, case_gap)
    else:  # CSV, and a folder of recordings, which the CSV reader refuses with a sentence
        types = [p.stem for p in Path(objects).glob("*.csv")] if objects is not None else []
        log, found = _read_csv(path, mapping, case, case_gap, types)
    if objects is None:
        return log, found, None
    return log, found, read_object_tables(Path(objects), log, path)


def read_csv(
    path: str | Path,
    mapping: Mapping[str, str] | None = None,
    case: str | None = None,
    case_gap: Gap = None,
) -> pd.DataFrame:
    """Read a CSV event log (UTF-8, a header line, comma-separated)."""
    return _read_csv(Path(path), mapping, case, case_gap)[0]


def read_xes(
    path: str | Path,
    mapping: Mapping[str, str] | None = None,
    case: str | None = None,
    case_gap: Gap = None,
) -> pd.DataFrame:
    """Read an XES event log; trace attributes become ``case:<key>`` columns."""
    return _read_xes(Path(path), mapping, case, case_gap)[0]


def _read_csv(
    path: Path,
    mapping: Mapping[str, str] | None,
    case: str | None,
    case_gap: Gap,
    objects: Sequence[str] = (),
) -> tuple[pd.DataFrame, Reading]:
    """``objects``: object types whose columns hold ids, which stay text ("12", not 12.0)."""
    text = _read_text(path)
    header = _csv_header(path, text)
    renames = column_mapping(path, list(header), mapping)
    text_columns = [src for src, canonical in renames.items() if canonical in TEXT_COLUMNS]
    if case is not None:
        text_columns.append(case)
    kinds = {reading.normalised(kind) for kind in objects}
    text_columns += [name for name in header if reading.normalised(name) in kinds]
    times = next((src for src, canonical in renames.items() if canonical == schema.TIMESTAMP), None)
    table, missing = _csv_table(path, text, text_columns, times)
    lines = pd.Series(range(2, len(table) + 2), index=table.index)  # line 1 is the header
    return canonical_log(path, table, renames, lines, case, case_gap, missing)


def _csv_header(path: Path, text: str) -> list[str]:
    """The column names of line 1, refused if a name is repeated (pandas would silently read
    the second ``activity`` as ``activity.1``) or if the file is JSON (an OCEL log, say)."""
    if text.lstrip().startswith(("{", "[")):
        raise InputError(
            f"{path} is JSON, not CSV: an OCEL 2.0 log is read as one when its name ends in "
            ".jsonocel or .json."
        )
    try:
        names = next(csv.reader(_lines(text), strict=True), [])
    except csv.Error as error:
        raise InputError(f"{path} line 1: the header is not readable CSV ({error}).") from None
    if not any(name.strip() for name in names):
        raise InputError(f"{path} line 1 names no columns: the first line must be the header.")
    repeated = sorted({name for name in names if names.count(name) > 1})
    if repeated:
        positions = [i + 1 for i, name in enumerate(names) if name == repeated[0]]
        raise InputError(
            f"{path} line 1: the column {repeated[0]!r} appears {len(positions)} times "
            f"(columns {', '.join(map(str, positions))}); give each column its own name."
        )
    return names


def _lines(text: str) -> Iterator[str]:
    """The lines of ``text`` one by one, each cut when it is asked for (the header alone
    reads one line, not a copy of the whole file)."""
    begin = 0
    while begin < len(text):
        end = text.find("\n", begin)
        end = len(text) if end == -1 else end + 1
        yield text[begin:end]
        begin = end


def _csv_table(
    path: Path, text: str, text_columns: list[str], times: str | None = None
) -> tuple[pd.DataFrame, dict[str, int]]:
    """The CSV's cells with the missing markers cleared, and how many per column.

    The markers are ours to decide, not pandas' (its own list takes "NA" for missing and
    leaves "-" as a value). Markers as whole cells are cleared by the parser itself;
    only a file with blanks around a marker is read as text and cleared cell by cell. Most
    files are read by pyarrow's reader (:func:`.reading.arrow_csv`); one it may read
    otherwise than pandas, and one it cannot read, by pandas' parser, whose reading and
    error sentences are the rule.
    """
    if (table := reading.arrow_csv(text, text_columns, times)) is not None:
        return table, _missing_counts(table)
    try:
        # index_col=False: a first row with more cells than the header would otherwise turn
        # the first column into the index; pandas warns instead, and the warning is an error.
        with warnings.catch_warnings():
            warnings.simplefilter("error", pd.errors.ParserWarning)
            if reading.has_padded_markers(text):
                table = pd.read_csv(
                    io.StringIO(text), dtype=str, keep_default_na=False, index_col=False
                )
                missing = reading.mark_missing(table)
                return reading.typed_columns(table, text_columns), missing
            table = pd.read_csv(
                io.StringIO(text),
                dtype=dict.fromkeys(text_columns, str),
                keep_default_na=False,
                na_values=sorted(reading.MISSING_MARKERS),
                index_col=False,
            )
            if huge := [c for c in reading.huge_integer_columns(table) if c not in text_columns]:
                return _csv_table(path, text, [*text_columns, *huge], times)
    except pd.errors.ParserWarning:
        raise InputError(_long_row(path, text)) from None
    except (pd.errors.ParserError, pd.errors.EmptyDataError, ValueError, csv.Error) as error:
        raise InputError(f"{path} is not a readable CSV file: {_one_line(error)}") from None
    return table, _missing_counts(table)


def _missing_counts(table: pd.DataFrame) -> dict[str, int]:
    counts = table.isna().sum()  # every NaN is a marker: no other value reads as one
    return {str(column): int(n) for column, n in counts.items() if n}


def _long_row(path: Path, text: str) -> str:
    """Which row has more cells than the header has names (found only once there is one)."""
    rows = csv.reader(io.StringIO(text))
    with suppress(csv.Error):  # a line csv cannot split (a lone CR): the sentence below
        width = len(next(rows))
        for row in rows:
            if len(row) > width:
                return (
                    f"{path} line {rows.line_num}: {len(row)} cells, but the header names "
                    f"{width} columns."
                )
    return f"{path}: a row has more cells than the header names columns."


def _read_xes(
    path: Path, mapping: Mapping[str, str] | None, case: str | None, case_gap: Gap
) -> tuple[pd.DataFrame, Reading]:
    _require_content(path)
    table, lines = _parse_xes(path)
    missing = reading.mark_missing(table)
    table = table.infer_objects()  # an int column whose markers were text is numbers again
    renames = column_mapping(path, list(table.columns), mapping)
    return canonical_log(path, table, renames, lines, case, case_gap, missing, traces=True)


# -- OCEL 2.0 --------------------------------------------------------------------------------

_OCEL_COLUMNS = {
    ocel.EVENT_ID: schema.EVENT_ID,
    ocel.ACTIVITY: schema.ACTIVITY,
    ocel.TIME: schema.TIMESTAMP,
}


def _read_ocel(
    path: Path, mapping: Mapping[str, str] | None, case: str | None, case_gap: Gap
) -> tuple[pd.DataFrame, Reading, Objects]:
    """The events with one column per object type; the objects beside them. An OCEL log has
    no cases: unless ``case`` or ``case_gap`` says otherwise it is one, and each object's
    events follow one another over the whole log."""
    found = ocel.read_ocel(path)
    events = found.events
    attributes = [c for c in events.columns if c not in _OCEL_COLUMNS]
    columns = entity_columns(path, found.objects.types, attributes)
    objects = dataclasses.replace(found.objects, columns=columns)
    cells = entity_cells(events[ocel.EVENT_ID], objects)
    table = events.assign(**cells)
    renames = {
        source: target
        for source, target in column_mapping(path, attributes, mapping).items()
        if target not in _OCEL_COLUMNS.values()
    } | _OCEL_COLUMNS
    lines = pd.Series(range(1, len(table) + 1), index=table.index)
    log, how = canonical_log(path, table, renames, lines, case, case_gap)
    how.columns.update(dict.fromkeys(objects.entity_types, "objects (entity type)"))
    # OCEL's events are instants by the standard: no pairs is no finding
    how.warnings = [w for w in how.warnings if w not in reading.no_pairs_warning(log)]
    if case is None and case_gap is None:
        how.case = "no case: an object-centric log, each object's events in one sequence"
        how.warnings = [w for w in how.warnings if w not in reading.days_warning(path, log)]
        how.session_gap = None
    return log, how, objects


# -- Parquet ---------------------------------------------------------------------------------


def _read_parquet(
    path: Path, mapping: Mapping[str, str] | None, case: str | None, case_gap: Gap
) -> tuple[pd.DataFrame, Reading]:
    table = _parquet_table(path).to_pandas()
    missing = {str(c): int(n) for c, n in table.isna().sum().items() if n}
    for column, count in reading.mark_missing(table).items():
        missing[column] = missing.get(column, 0) + count
    renames = column_mapping(path, list(table.columns), mapping)
    lines = pd.Series(range(1, len(table) + 1), index=table.index)
    return canonical_log(path, table, renames, lines, case, case_gap, missing)


def _parquet_table(path: Path) -> pa.Table:
    """A Parquet file, robotale's dataset folder (checked against its manifest) or another
    Hive-partitioned folder of Parquet files, as one table."""
    if not path.exists():
        raise InputError(f"{path} does not exist.")
    if path.is_dir():
        folder = place(path)
        manifest = dataset.read_manifest(folder)
        if manifest is not None:
            return dataset.read_table(folder, manifest)
    try:
        if path.is_dir():
            # here, not at the top: pyarrow's datasets are measured start-up that only a
            # folder of Parquet files needs (a CSV's ingest imports this module)
            import pyarrow.dataset as pads

            return pads.dataset(path, format="parquet", partitioning="hive").to_table()
        return pq.read_table(path)
    except (pa.ArrowException, OSError) as error:
        reason = " ".join(str(error).split())[:200]
        raise InputError(f"{path} is not a readable Parquet event log ({reason}).") from None


# -- XES -------------------------------------------------------------------------------------

_XES_VALUES: dict[str, Callable[[str], object]] = {
    "string": str,
    "id": str,
    "date": str,  # parsed with the other timestamps
    "int": int,
    "float": float,
    "boolean": lambda value: value.strip().lower() == "true",
}


def _parse_xes(path: Path) -> tuple[pd.DataFrame, pd.Series]:
    """Events as rows (trace attributes as ``case:<key>``) and each event's line in the file."""
    rows: list[dict[str, object]] = []
    lines: list[int] = []
    parser = etree.iterparse(
        str(path),
        events=("end",),
        tag=("{*}trace",),
        resolve_entities=False,
        no_network=True,
        huge_tree=True,
    )
    try:
        for number, (_, trace) in enumerate(parser, start=1):
            case = {f"case:{k}": v for k, v in _xes_attributes(path, trace).items()}
            case.setdefault(schema.CASE, str(number))
            for event in trace.iterchildren("{*}event"):
                rows.append({**case, **_xes_attributes(path, event)})
                lines.append(event.sourceline or 0)
            trace.clear()
    except etree.XMLSyntaxError as error:
        raise InputError(f"{path} is not valid XES: {error.msg} (line {error.lineno}).") from None
    if not rows:
        raise InputError(f"{path} has no events (no <trace> with an <event>).")
    return pd.DataFrame(rows), pd.Series(lines)


def _xes_attributes(path: Path, element: object) -> dict[str, object]:
    """The simple attributes directly under a trace or event (nested ones are skipped)."""
    values: dict[str, object] = {}
    for child in element.iterchildren():  # type: ignore[attr-defined]
        kind = etree_localname(child.tag)
        convert = _XES_VALUES.get(kind)
        key = child.get("key")
        if convert is None or key is None:
            continue
        raw = child.get("value", "")
        if raw.strip() in reading.MISSING_MARKERS:
            values[key] = raw  # a missing marker: counted and cleared with the CSV's
            continue
        try:
            values[key] = convert(raw)
        except ValueError:
            raise InputError(
                f"{path} line {child.sourceline}: the {kind} attribute {key!r} has the value "
                f"{child.get('value')!r}."
            ) from None
    return values


def etree_localname(tag: object) -> str:
    return tag.rpartition("}")[2] if isinstance(tag, str) else ""


# -- steps shared by both formats --------------------------------------------------------------


def canonical_log(
    path: Path,
    table: pd.DataFrame,
    renames: Mapping[str, str],
    lines: pd.Series,
    case: str | None = None,
    case_gap: Gap = None,
    missing: Mapping[str, int] | None = None,
    traces: bool = False,
) -> tuple[pd.DataFrame, Reading]:
    """Rename, check and normalise a raw table into the canonical event log, and say how.

    ``missing`` counts the cells already cleared as missing; ``traces`` says the cases are XES
    traces.
    """
    if table.empty:
        raise InputError(f"{path} has no events, only a header.")
    if case is not None and case not in table.columns:
        raise InputError(
            f"{path} has no column {case!r} for --case; its columns are "
            f"{listing(list(table.columns))}."
        )
    gap = reading.parse_duration(case_gap) if case_gap is not None else None
    log = table.rename(columns=dict(renames))
    if case is not None:
        log[schema.CASE] = table[case].astype("string")
    _check_columns(path, log)
    log[schema.TIMESTAMP] = parse_timestamps(path, log[schema.TIMESTAMP], lines)
    _require_values(path, log, schema.ACTIVITY, lines)
    kinds = reading.event_kinds(log)
    dropped = reading.dropped_rows(kinds, lines)
    keep = reading.understood(kinds).to_numpy(bool)
    ids = next(
        (src for src, canonical in renames.items() if canonical == schema.EVENT_ID),
        schema.EVENT_ID if schema.EVENT_ID in table.columns else None,
    )
    copies, copied = reading.exact_copies(table, lines, keep, ids)
    dropped |= copied
    keep = keep & ~copies
    if not keep.any():
        raise InputError(f"{path}: no row is an event ({next(iter(dropped))}).")
    log, kinds = log[keep].copy(), kinds[keep]
    notes = reading.lifecycle_columns(log, kinds)
    case_text, warnings = _cases(path, log, renames, case, gap, traces)
    if schema.MSG_ROLE in log.columns:
        _require_text(path, log, schema.MSG_ROLE, lines)
        log[schema.MSG_ROLE] = log[schema.MSG_ROLE].astype("string").str.strip().str.lower()
    notes += reading.message_roles_from_ends(log)
    log[schema.EVENT_ID] = _event_ids(path, log, lines)
    for column in TEXT_COLUMNS:
        if column in log.columns:
            log[column] = log[column].astype("string")
    log = log.reset_index(drop=True)
    robots, robot_warnings = reading.robot_types(log)
    found = Reading(
        source=path.name,
        columns=reading.column_roles(list(table.columns), renames, case),
        case=case_text,
        cases=int(log[schema.CASE].nunique()),
        robots=robots,
        events=_event_counts(kinds),
        pairing=reading.pairing_description(log, renames),
        rows=len(table),
        missing=dict(missing or {}),
        dropped=dropped,
        notes=notes,
        warnings=warnings
        + robot_warnings
        + reading.single_value_warnings(log, renames)
        + reading.no_pairs_warning(log),
        # the only warning _cases gives is that of a log of several days without cases
        session_gap=reading.SESSION_GAP if warnings else None,
    )
    return log, found


def _require_text(path: Path, log: pd.DataFrame, column: str, lines: pd.Series) -> None:
    """Refuse a typed value (an XES ``<boolean>`` or ``<int>``) in a column that holds words."""
    values = log[column]
    if isinstance(values.dtype, pd.StringDtype):  # a text column holds nothing else
        return
    typed = values.notna() & ~values.map(lambda value: isinstance(value, str))
    if typed.any():
        first = typed.idxmax()
        value = values[first]
        kind = "boolean" if isinstance(value, bool | np.bool_) else type(value).__name__
        raise InputError(
            f"{path} line {lines[first]}: the {reading.ROLE_NAMES.get(column, column)} is the "
            f"{kind} {str(value).lower()}, not text; give {column} as text (send or receive)."
        )


def _one_line(error: BaseException) -> str:
    return " ".join(str(error).split())


def _cases(
    path: Path,
    log: pd.DataFrame,
    renames: Mapping[str, str],
    case: str | None,
    gap: pd.Timedelta | None,
    traces: bool,
) -> tuple[str, list[str]]:
    """Fill the case column where the log has none; how cases are told apart, and warnings."""
    if schema.CASE in log.columns:
        column = case or next((c for c, r in renames.items() if r == schema.CASE), None)
        told_by = "its XES traces" if traces and case is None else f"the column {column!r}"
        if gap is not None:
            raise InputError(
                f"{path} tells its cases apart by {told_by}; --case-gap splits only a log "
                "without a case column."
            )
        return told_by, []
    if gap is not None:
        log[schema.CASE] = reading.cases_by_gap(log[schema.TIMESTAMP], gap)
        return f"a new case after every pause of {reading.duration_text(gap)} or more", []
    log[schema.CASE] = SINGLE_CASE
    return "no case column: one case", reading.days_warning(path, log)


def parse_timestamps(path: Path, values: pd.Series, lines: pd.Series) -> pd.Series:
    """Timezone-aware timestamps (UTC when the file gives no offset).

    One offset for the whole log is kept as it is; mixed offsets are converted to UTC.
    """
    if pd.api.types.is_datetime64_any_dtype(values):
        parsed = values
    else:
        text = values.astype("string").str.strip()
        parsed = _to_datetime(text)
        # pandas reads some text that is no time as year 0 ("/1"), which Python's dates and
        # everything built on them cannot hold
        bad = parsed.isna() | (parsed.dt.year < 1)
        if bad.any():
            row = bad.idxmax()
            shown = "" if pd.isna(text[row]) else text[row]
            raise InputError(
                f"{path} line {lines[row]}: cannot read the timestamp {shown!r} "
                "(expected ISO 8601, e.g. 2023-05-16T10:27:08.918+01:00)."
            )
    if parsed.dt.tz is None:
        parsed = parsed.dt.tz_localize("UTC")
    # one unit whatever the file gave (six decimals or nine): a log's times compare as read
    return parsed.dt.as_unit("ns")


def _to_datetime(text: pd.Series) -> pd.Series:
    # no cache of distinct values: a log's times are nearly all distinct, and building it
    # costs more than it saves
    try:
        return pd.to_datetime(text, format="ISO8601", errors="coerce", cache=False)
    except ValueError:  # mixed offsets, or offsets mixed with naive times
        return pd.to_datetime(text, format="ISO8601", errors="coerce", utc=True, cache=False)


def _check_columns(path: Path, log: pd.DataFrame) -> None:
    for required in (schema.ACTIVITY, schema.TIMESTAMP):
        if required not in log.columns:
            names = ", ".join(SYNONYMS[required])
            short = schema.CSV_NAMES[required]
            raise InputError(
                f"{path} has no {short} column (looked for {names}); "
                f"name yours with --map COLUMN={short}."
            )
    for column in log.columns:
        if not schema.is_property_name(column):
            raise InputError(
                f"{path} has a column named {column!r}, which cannot become a property name "
                "(use letters, digits, _ : . - and blanks); rename it with --map."
            )
    duplicates = log.columns[log.columns.duplicated()].tolist()
    if duplicates:
        raise InputError(
            f"{path}: more than one column would be {duplicates[0]!r}; map only one of them there."
        )


def _require_values(path: Path, log: pd.DataFrame, column: str, lines: pd.Series) -> None:
    empty = log[column].isna() | (log[column].astype("string").str.strip() == "")
    if empty.any():
        raise InputError(
            f"{path} line {lines[empty.idxmax()]}: the {schema.CSV_NAMES[column]} is empty."
        )


def _event_ids(path: Path, log: pd.DataFrame, lines: pd.Series) -> pd.Series:
    if schema.EVENT_ID not in log.columns:
        # the row's position in the file, so ids stay put when rows are dropped
        return pd.Series(log.index.astype(str), index=log.index, dtype="string")
    ids = log[schema.EVENT_ID].astype("string").str.strip()
    missing = ids.isna() | (ids == "")
    if missing.any():
        raise InputError(f"{path} line {lines[missing.idxmax()]}: the event_id is empty.")
    repeated = ids.duplicated(keep=False)
    if repeated.any():
        first = ids[repeated].iloc[0]
        where = lines[ids == first].tolist()[:2]
        raise InputError(
            f"{path}: the event_id {first!r} appears more than once (lines {where[0]} and "
            f"{where[1]}); event ids must be unique."
        )
    return ids


def _require_content(path: Path) -> bytes:
    if not path.exists():
        raise InputError(f"{path} does not exist.")
    if path.is_dir():
        raise InputError(f"{path} is a directory, not an event log file.")
    data = path.read_bytes()
    if not data.strip():
        raise InputError(f"{path} is empty.")
    return data


def _read_text(path: Path) -> str:
    data = _require_content(path)
    try:
        text = data.decode("utf-8-sig")
    except UnicodeDecodeError as error:
        line = data[: error.start].count(b"\n") + 1
        raise InputError(
            f"{path} is not UTF-8 text (byte 0x{data[error.start]:02x} on line {line}); "
            "save it as UTF-8."
        ) from None
    if not text.strip():
        raise InputError(f"{path} holds nothing but a byte order mark: it has no header line.")
    return text


def _event_counts(kinds: pd.Series) -> dict[str, int]:
    """Events by kind; aborted and cancelled ends only where the log has them."""
    found = kinds.value_counts()  # one pass, not a comparison per kind
    counts = {kind: int(found.get(kind, 0)) for kind in (*reading.KINDS, *reading.OUTCOMES)}
    return {k: n for k, n in counts.items() if n or k in reading.KINDS}
