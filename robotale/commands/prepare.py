"""``robotale prepare``: rosbag2 recordings into an event log (CSV, a Parquet dataset, XES,
OCEL 2.0)."""

from __future__ import annotations

import tempfile
from pathlib import Path
from typing import Any

import pandas as pd

from robotale.errors import InputError
from robotale.eventlog import writers
from robotale.eventlog.options import PrepareOptions
from robotale.eventlog.prepare import find_runs, prepare_dataset
from robotale.eventlog.preparing import (
    kept_runs,
    preparation_warnings,
    prepare_recordings,
    report_choice,
    skipping,
)
from robotale.eventlog.readers import read_log
from robotale.fame_runtime.manifest import read_manifests
from robotale.storage import Place, is_url, local_path, place


def prepare_command(
    source: Path,
    *,
    out: str | Path | None = None,
    xes: Path | None = None,
    ocel: Path | None = None,
    executor: str | None = None,
    skip_bad: bool = False,
    **options: Any,
) -> int:
    """Write the event log of the recordings at ``source`` as CSV (``out``, by default
    ``<source name>.csv`` when no other output is asked for) or, when ``out`` ends in
    ``.parquet``, as a Parquet dataset partitioned by run; also XES and/or OCEL 2.0.
    ``out`` may be an fsspec URL. ``executor`` (``local[:N]``, ``dask://HOST:PORT``) reads the
    runs in parallel; ``options`` are the fields of
    :class:`~robotale.eventlog.options.PrepareOptions`. With ``skip_bad``
    a run that cannot be read is left out, named with why on stderr."""
    if out is not None and is_dataset_name(out):
        return _prepare_dataset(source, str(out), xes, ocel, executor, options, skip_bad)
    csv = out or (None if xes or ocel else f"{source.resolve().name}.csv")
    for target in (xes, ocel):  # all refused before hours of preparation, not after
        if target is not None:
            writers.check_target(target)
    csv_place = _csv_place(csv) if csv is not None else None
    skipped: list[Path] | None = [] if skip_bad else None
    log = prepare_recordings(
        source, PrepareOptions.given(options), executor=executor, skipped=skipped
    )
    written = []
    if csv_place is not None:
        _write_csv(log, csv_place)
        written.append(csv_place.text)
    written += _also_written(log, source, xes, ocel)
    cases = log["case:concept:name"].nunique()
    print(f"{len(log)} events from {cases} run(s) written to {', '.join(written)}")
    if skipped is not None:
        print(kept_runs(cases, skipped))
    return 0


def _also_written(
    log: pd.DataFrame, source: Path, xes: Path | None, ocel: Path | None
) -> list[str]:
    """Write the XES and OCEL 2.0 files asked for; their names."""
    written = []
    if xes:
        writers.write_xes(log, xes, name=source.resolve().name)
        written.append(str(xes))
    if ocel:
        writers.write_ocel(log, ocel, runs=read_manifests(find_runs(source)))
        written.append(str(ocel))
    return written


def is_dataset_name(out: str | Path) -> bool:
    """Whether ``--out`` names a Parquet dataset (``NAME.parquet``, a folder)."""
    return str(out).rstrip("/").lower().endswith(".parquet")


def _csv_place(csv: str | Path) -> Place:
    """Where the CSV goes, refused (a folder ...) before anything is read."""
    if not is_url(csv):
        writers.check_target(csv)
    target = place(csv)
    if not target.local and target.is_dir():
        raise InputError(f"{csv} is a folder: give the name of the file to write.")
    return target


def _write_csv(log: pd.DataFrame, target: Place) -> None:
    if target.local:
        writers.write_csv(log, target.text)
        return
    with tempfile.TemporaryDirectory() as folder:
        staged = Path(folder) / target.name
        writers.write_csv(log, staged)
        target.write_whole(staged.read_bytes())


def _prepare_dataset(
    source: Path,
    out: str,
    xes: Path | None,
    ocel: Path | None,
    executor: str | None,
    options: dict[str, Any],
    skip_bad: bool,
) -> int:
    """``prepare --out NAME.parquet``: every run written by the process that prepares it; XES
    and OCEL, if asked for, from the dataset read back. With ``skip_bad`` a run that cannot be
    read is left out, named with why on stderr."""
    local = local_path(out)
    if (xes or ocel) and local is None:
        raise InputError(
            f"--xes and --ocel are written from a dataset on this machine, not from {out}: "
            "write the dataset to a local folder, or leave them out."
        )
    for target in (xes, ocel):
        if target is not None:
            writers.check_target(target)
    skipped: list[Path] | None = [] if skip_bad else None
    with preparation_warnings():
        manifest = prepare_dataset(
            source,
            out,
            progress=True,
            report=report_choice,
            executor=executor,
            skip_bad=None if skipped is None else skipping(skipped),
            **PrepareOptions.given(options).keywords(),
        )
    written = [out]
    if local is not None and (xes or ocel):
        written += _also_written(read_log(local), source, xes, ocel)
    print(
        f"{manifest['rows']} events from {len(manifest['parts'])} run(s) written to "
        f"{', '.join(written)}"
    )
    if skipped is not None:
        print(kept_runs(len(manifest["parts"]), skipped))
    return 0
