"""The log a path holds, whatever its kind: :func:`open_log` asks
:func:`~robotale.eventlog.logkinds.kind_of` once and reads the file or prepares the
recordings, so ``ingest`` (and whatever else takes a path) never decides itself."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

import pandas as pd

from robotale.errors import InputError
from robotale.eventlog.logkinds import PARQUET, RECORDINGS, LogKind, kind_of
from robotale.eventlog.objects import Objects
from robotale.eventlog.options import PrepareOptions
from robotale.eventlog.readers import Gap, parse_mapping, read_with_objects
from robotale.eventlog.reading import Reading


@dataclass(frozen=True)
class OpenedLog:
    """A log read from a path: its events, how a file was read (None for recordings, whose
    preparation says so itself), its objects where it is object-centric, and its kind."""

    events: pd.DataFrame
    reading: Reading | None
    objects: Objects | None
    kind: LogKind


def open_log(
    path: Path,
    *,
    mapping: Sequence[str] = (),
    case: str | None = None,
    case_gap: Gap = None,
    objects: Path | None = None,
    preparation: PrepareOptions | None = None,
    skipped: list[Path] | None = None,
) -> OpenedLog:
    """The log at ``path``: a file read with the ``--map`` items ``mapping``, ``case``,
    ``case_gap`` and its ``objects`` folder, or recordings prepared with ``preparation``
    (``skipped``: see :func:`~robotale.eventlog.preparing.prepare_recordings`)."""
    kind = kind_of(path)
    if kind is RECORDINGS:
        _refuse_file_options(path, mapping, case, case_gap, objects)
        # here, not at the top: the recordings' preparation (the bag reader, ROS types, the
        # worker pools) is measured start-up a CSV's or Parquet's ingest does not need
        from robotale.eventlog.preparing import prepare_recordings

        events = prepare_recordings(path, preparation, skipped=skipped)
        return OpenedLog(events, None, None, kind)
    events, reading, found = read_with_objects(
        path, parse_mapping(mapping), case, case_gap, objects
    )
    return OpenedLog(events, reading, found, kind)


def _refuse_file_options(
    path: Path,
    mapping: Sequence[str],
    case: str | None,
    case_gap: Gap,
    objects: Path | None,
) -> None:
    if objects is not None:
        raise InputError(
            f"{path} holds recordings: --objects applies to a CSV event log with one "
            "column per object type."
        )
    if mapping or case:
        raise InputError(
            f"{path} holds recordings: --map and --case apply to CSV and XES files "
            "(each run of a recording is its own case)."
        )
    if case_gap:
        raise InputError(
            f"{path} holds recordings: --case-gap applies to CSV and XES files "
            "(each run of a recording is its own case)."
        )


def log_name(path: Path) -> str:
    """A log's default name: the file's stem, or the folder's name (also for ``.``)."""
    if kind_of(path) is PARQUET:  # a dataset folder is named like a file: agri.parquet
        return path.resolve().stem
    return path.resolve().name if path.is_dir() else path.stem
