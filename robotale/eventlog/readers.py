"""Read an event log from CSV or XES into the canonical DataFrame of :mod:`.schema`.

Columns are recognised by their usual names (``time``, ``timestamp``, ``time:timestamp``;
``activity``, ``concept:name``; ``resource``, ``robot_id``, ``org:resource`` for the robot ...;
see :data:`SYNONYMS`), or mapped explicitly with ``mapping={"Zeit": "time"}`` (the command
line's ``--map Zeit=time``). Without a case column the whole log is one case (``"1"``), unless
``case=`` names the column that tells cases apart. In XES the trace's name is the case. Rows
keep their order in the file, which breaks ties between equal timestamps later on.

Every problem is one :class:`~robotale.errors.InputError` naming the file and, where there is
one, the line.
"""

from __future__ import annotations

import io
import re
from collections.abc import Mapping, Sequence
from pathlib import Path

import pandas as pd

from robotale.errors import InputError
from robotale.eventlog import schema

#: canonical column -> names it is recognised by (compared ignoring case, blanks, "_" and "-").
SYNONYMS: dict[str, tuple[str, ...]] = {
    schema.CASE: ("case", "case:concept:name", "case_id", "trace", "trace_id"),
    schema.ACTIVITY: ("activity", "concept:name", "activity_name", "task"),
    schema.TIMESTAMP: ("time", "timestamp", "time:timestamp", "datetime"),
    schema.LIFECYCLE: ("lifecycle", "lifecycle:transition", "transition"),
    schema.STATE: ("state", "lifecycle:state"),
    schema.ROBOT: ("robot", "resource", "robot_id", "org:resource", "agent"),
    schema.ROBOT_TYPE: ("robot_type", "org:role"),
    schema.MSG_ID: ("msg_id", "message_id"),
    schema.MSG_ROLE: ("msg_role", "message_role"),
    schema.MSG_PAYLOAD: ("msg_payload", "payload", "message_payload"),
    schema.EVENT_ID: ("event_id", "id"),
    schema.EXECUTION_ID: ("execution_id", "concept:instance", "activity_instance"),
    schema.X: ("x",),
    schema.Y: ("y",),
    schema.Z: ("z",),
    schema.BATTERY: ("battery",),
}
#: columns whose values are names, never numbers ("38" stays the case "38").
TEXT_COLUMNS = (
    schema.CASE,
    schema.ACTIVITY,
    schema.LIFECYCLE,
    schema.STATE,
    schema.ROBOT,
    schema.ROBOT_TYPE,
    schema.MSG_ID,
    schema.MSG_ROLE,
    schema.MSG_PAYLOAD,
    schema.EVENT_ID,
    schema.EXECUTION_ID,
)
SINGLE_CASE = "1"


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
    path: str | Path, mapping: Mapping[str, str] | None = None, case: str | None = None
) -> pd.DataFrame:
    """Read a ``.csv`` or ``.xes`` event log (chosen by the file's extension)."""
    path = Path(path)
    if path.suffix.lower() == ".xes":
        return read_xes(path, mapping, case)
    return read_csv(path, mapping, case)


def read_csv(
    path: str | Path, mapping: Mapping[str, str] | None = None, case: str | None = None
) -> pd.DataFrame:
    """Read a CSV event log (UTF-8, a header line, comma-separated)."""
    path = Path(path)
    text = _read_text(path)
    header = pd.read_csv(io.StringIO(text), nrows=0).columns
    renames = column_mapping(path, list(header), mapping)
    text_columns = [src for src, canonical in renames.items() if canonical in TEXT_COLUMNS]
    if case is not None:
        text_columns.append(case)
    try:
        table = pd.read_csv(io.StringIO(text), dtype=dict.fromkeys(text_columns, str))
    except (pd.errors.ParserError, ValueError) as error:
        raise InputError(f"{path} is not a readable CSV file: {error}") from None
    lines = pd.Series(range(2, len(table) + 2), index=table.index)  # line 1 is the header
    return canonical_log(path, table, renames, lines, case)


def read_xes(
    path: str | Path, mapping: Mapping[str, str] | None = None, case: str | None = None
) -> pd.DataFrame:
    """Read an XES event log; trace attributes become ``case:<key>`` columns."""
    path = Path(path)
    _require_content(path)
    table, lines = _parse_xes(path)
    renames = column_mapping(path, list(table.columns), mapping)
    return canonical_log(path, table, renames, lines, case)


# -- XES -------------------------------------------------------------------------------------

_XES_VALUES = {
    "string": str,
    "id": str,
    "date": str,  # parsed with the other timestamps
    "int": int,
    "float": float,
    "boolean": lambda value: value.strip().lower() == "true",
}


def _parse_xes(path: Path) -> tuple[pd.DataFrame, pd.Series]:
    """Events as rows (trace attributes as ``case:<key>``) and each event's line in the file."""
    from lxml import etree

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
        try:
            values[key] = convert(child.get("value", ""))
        except ValueError:
            raise InputError(
                f"{path} line {child.sourceline}: the {kind} attribute {key!r} has the value "
                f"{child.get('value')!r}."
            ) from None
    return values


def etree_localname(tag: object) -> str:
    return tag.rpartition("}")[2] if isinstance(tag, str) else ""


# -- steps shared by both formats --------------------------------------------------------------


def column_mapping(
    path: Path, columns: list[str], explicit: Mapping[str, str] | None = None
) -> dict[str, str]:
    """Source column -> canonical column, explicit entries first, then :data:`SYNONYMS`."""
    explicit = dict(explicit or {})
    for source in explicit:
        if source not in columns:
            raise InputError(
                f"{path} has no column {source!r} to map; its columns are {_listing(columns)}."
            )
    renames = {source: _canonical_name(target) for source, target in explicit.items()}
    taken = set(renames.values())
    for canonical, names in SYNONYMS.items():
        if canonical in taken:
            continue
        wanted = [_normalised(name) for name in names]
        found = [c for c in columns if c not in renames and _normalised(c) in wanted]
        if found:
            renames[min(found, key=lambda c: wanted.index(_normalised(c)))] = canonical
            taken.add(canonical)
    return renames


def canonical_log(
    path: Path,
    table: pd.DataFrame,
    renames: Mapping[str, str],
    lines: pd.Series,
    case: str | None = None,
) -> pd.DataFrame:
    """Rename, check and normalise a raw table into the canonical event log."""
    if table.empty:
        raise InputError(f"{path} has no events, only a header.")
    if case is not None and case not in table.columns:
        raise InputError(
            f"{path} has no column {case!r} for --case; its columns are "
            f"{_listing(list(table.columns))}."
        )
    log = table.rename(columns=dict(renames))
    if case is not None:
        log[schema.CASE] = table[case].astype("string")
    _check_columns(path, log, renames)
    log[schema.TIMESTAMP] = parse_timestamps(path, log[schema.TIMESTAMP], lines)
    _require_values(path, log, schema.ACTIVITY, lines)
    if schema.CASE not in log.columns:
        log[schema.CASE] = SINGLE_CASE
    log[schema.LIFECYCLE] = _lifecycle(log)
    if schema.MSG_ROLE in log.columns:
        log[schema.MSG_ROLE] = log[schema.MSG_ROLE].str.strip().str.lower()
    log[schema.EVENT_ID] = _event_ids(path, log, lines)
    for column in TEXT_COLUMNS:
        if column in log.columns:
            log[column] = log[column].astype("string")
    return log.reset_index(drop=True)


def parse_timestamps(path: Path, values: pd.Series, lines: pd.Series) -> pd.Series:
    """Timezone-aware timestamps (UTC when the file gives no offset).

    One offset for the whole log is kept as it is; mixed offsets are converted to UTC.
    """
    if pd.api.types.is_datetime64_any_dtype(values):
        parsed = values
    else:
        text = values.astype("string").str.strip()
        parsed = _to_datetime(text)
        bad = parsed.isna()
        if bad.any():
            row = bad.idxmax()
            shown = "" if pd.isna(text[row]) else text[row]
            raise InputError(
                f"{path} line {lines[row]}: cannot read the timestamp {shown!r} "
                "(expected ISO 8601, e.g. 2023-05-16T10:27:08.918+01:00)."
            )
    if parsed.dt.tz is None:
        parsed = parsed.dt.tz_localize("UTC")
    return parsed


def _to_datetime(text: pd.Series) -> pd.Series:
    try:
        return pd.to_datetime(text, format="ISO8601", errors="coerce")
    except ValueError:  # mixed offsets, or offsets mixed with naive times
        return pd.to_datetime(text, format="ISO8601", errors="coerce", utc=True)


def _check_columns(path: Path, log: pd.DataFrame, renames: Mapping[str, str]) -> None:
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


def _lifecycle(log: pd.DataFrame) -> pd.Series:
    # A log without lifecycle information records completed activities (pm4py's default).
    if schema.LIFECYCLE not in log.columns:
        return pd.Series(schema.COMPLETE, index=log.index, dtype="string")
    values = log[schema.LIFECYCLE].astype("string").str.strip().str.lower()
    return values.fillna(schema.COMPLETE)


def _event_ids(path: Path, log: pd.DataFrame, lines: pd.Series) -> pd.Series:
    if schema.EVENT_ID not in log.columns:
        return pd.Series([str(i) for i in range(len(log))], index=log.index, dtype="string")
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


def _canonical_name(target: str) -> str:
    """``time`` -> ``time:timestamp`` etc.; any other target is kept as the new name."""
    short_to_long = {short: long for long, short in schema.CSV_NAMES.items()}
    return short_to_long.get(target, target)


def _normalised(name: str) -> str:
    return re.sub(r"[\s_\-]", "", str(name)).lower()


def _listing(columns: list[str]) -> str:
    return ", ".join(repr(c) for c in columns[:20]) + (" ..." if len(columns) > 20 else "")


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
        return data.decode("utf-8-sig")
    except UnicodeDecodeError as error:
        line = data[: error.start].count(b"\n") + 1
        raise InputError(
            f"{path} is not UTF-8 text (byte 0x{data[error.start]:02x} on line {line}); "
            "save it as UTF-8."
        ) from None
