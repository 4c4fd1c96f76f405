"""``robotale prepare``: rosbag2 recordings into an event log; also the preparation that
``ingest`` and ``demo`` run on recordings."""

from __future__ import annotations

import sys
import tempfile
import warnings
from collections.abc import Callable, Iterator, Sequence
from contextlib import contextmanager
from pathlib import Path
from typing import Any

import pandas as pd

from robotale.errors import InputError
from robotale.eventlog import writers
from robotale.eventlog.enrich import PreparationWarning
from robotale.eventlog.prepare import TagFields, find_runs, prepare, prepare_dataset
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
    runs in parallel; ``options`` are those of :func:`prepare_recordings`. With ``skip_bad``
    a run that cannot be read is left out, named with why on stderr."""
    if out is not None and is_dataset_name(out):
        return _prepare_dataset(source, str(out), xes, ocel, executor, options, skip_bad)
    csv = out or (None if xes or ocel else f"{source.resolve().name}.csv")
    for target in (xes, ocel):  # all refused before hours of preparation, not after
        if target is not None:
            writers.check_target(target)
    csv_place = _csv_place(csv) if csv is not None else None
    skipped: list[Path] | None = [] if skip_bad else None
    log = prepare_recordings(source, executor=executor, skipped=skipped, **options)
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


def kept_runs(kept: int, skipped: Sequence[Path]) -> str:
    """How many runs a ``--skip-bad`` preparation kept, and which it left out."""
    left_out = f"; skipped {len(skipped)}: {', '.join(run.name for run in skipped)}"
    return f"kept {kept} of {kept + len(skipped)} run(s){left_out if skipped else ''}"


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
    skip_bad: bool = False,
) -> int:
    """``prepare --out NAME.parquet``: every run written by the process that prepares it; XES
    and OCEL, if asked for, from the dataset read back. With ``skip_bad`` a run that cannot
    be read is left out of the dataset, named with why on stderr."""
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
    skip = None if skipped is None else _skipping(skipped)
    with _preparation_warnings():
        manifest = prepare_dataset(
            source, out, progress=True, report=_report, executor=executor, skip_bad=skip,
            **_given(options),
        )  # fmt: skip
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


def prepare_recordings(
    source: Path,
    *,
    tags: str | None = None,
    tag_fields: Sequence[str] = (),
    perspectives: str | None = None,
    rate: float | None = None,
    msg_files: Sequence[str] = (),
    bag_time: bool = False,
    lifecycle: str | None = None,
    actions: str | None = None,
    state_topics: Sequence[str] = (),
    bt_log: str | None = None,
    auto: bool = False,
    distro: str | None = None,
    robot: str | None = None,
    executor: str | None = None,
    skipped: list[Path] | None = None,
) -> pd.DataFrame:
    """The event log of the recordings at ``source``; an option left ``None`` takes
    :func:`~robotale.eventlog.prepare.prepare`'s default (``executor``: read in this process).
    Given a list ``skipped``, a run that cannot be read is left out, added to it and named
    with why on stderr; without, it stops the preparation before anything is written."""
    options = {
        "tags": tags,
        "tag_fields": tag_fields,
        "perspectives": perspectives,
        "rate": rate,
        "msg_files": msg_files,
        "bag_time": bag_time,
        "lifecycle": lifecycle,
        "actions": actions,
        "state_topics": state_topics,
        "bt_log": bt_log,
        "auto": auto,
        "distro": distro,
        "robot": robot,
    }
    skip = None if skipped is None else _skipping(skipped)
    return prepare_reporting(source, executor=executor, skip_bad=skip, **_given(options))


def _skipping(skipped: list[Path]) -> Callable[[Path, str], None]:
    def skip(run: Path, why: str) -> None:
        skipped.append(run)
        print(f"robotale: skipped {run.name}: {why}", file=sys.stderr)

    return skip


def _given(options: dict[str, Any]) -> dict[str, Any]:
    """The command line's preparation options as :func:`prepare` takes them; one left
    ``None`` takes its default."""
    perspectives = options.get("perspectives")
    given: dict[str, Any] = {
        "tags": options.get("tags"),
        "perspectives": (
            None if perspectives is None else [p for p in perspectives.split(",") if p.strip()]
        ),
        "rate": options.get("rate"),
    }
    return {
        "tag_fields": TagFields.parse(options.get("tag_fields") or ()),
        "msg_files": options.get("msg_files") or (),
        "bag_time": bool(options.get("bag_time")),
        "lifecycle": options.get("lifecycle"),
        "actions": options.get("actions"),
        "states": list(options.get("state_topics") or ()),
        "bt_logs": options.get("bt_log"),
        "auto": bool(options.get("auto")),
        "distro": options.get("distro"),
        "robot": options.get("robot"),
        **{key: value for key, value in given.items() if value is not None},
    }


def prepare_reporting(source: Path, **options: Any) -> pd.DataFrame:
    """:func:`~robotale.eventlog.prepare.prepare` with a progress bar, its warnings (completes
    without a start ...) on stderr as one ``robotale: warning:`` line each."""
    with _preparation_warnings():
        return prepare(source, progress=True, report=_report, **options)


@contextmanager
def _preparation_warnings() -> Iterator[None]:
    """The preparation's warnings said on stderr, one ``robotale: warning:`` line each (also
    those said before a failure)."""
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always", PreparationWarning)
        try:
            yield
        finally:
            for warning in caught:
                if issubclass(warning.category, PreparationWarning):
                    print(f"robotale: warning: {warning.message}", file=sys.stderr)


def _report(text: str) -> None:
    """What the preparation chose (``--auto``), on stderr so that stdout stays the summary."""
    print(f"robotale: {text}", file=sys.stderr)
