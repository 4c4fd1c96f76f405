"""``robotale prepare``: rosbag2 recordings into an event log; also the preparation that
``ingest`` and ``demo`` run on recordings."""

from __future__ import annotations

import sys
import warnings
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import pandas as pd

from robotale.eventlog import writers
from robotale.eventlog.enrich import PreparationWarning
from robotale.eventlog.prepare import TagFields, find_runs, prepare
from robotale.fame_runtime.manifest import read_manifests


def prepare_command(
    source: Path,
    *,
    out: Path | None = None,
    xes: Path | None = None,
    ocel: Path | None = None,
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
    executor: str | None = None,
) -> int:
    """Write the event log of the recordings at ``source`` as CSV (``out``, by default
    ``<source name>.csv`` when no other output is asked for), XES and/or OCEL 2.0; ``executor``
    (``local[:N]``, ``dask://HOST:PORT``) reads the runs in parallel."""
    csv = out or (None if xes or ocel else Path(f"{source.resolve().name}.csv"))
    for target in (csv, xes, ocel):  # all refused before hours of preparation, not after
        if target is not None:
            writers.check_target(target)
    log = prepare_recordings(
        source,
        tags=tags,
        tag_fields=tag_fields,
        perspectives=perspectives,
        rate=rate,
        msg_files=msg_files,
        bag_time=bag_time,
        lifecycle=lifecycle,
        actions=actions,
        state_topics=state_topics,
        bt_log=bt_log,
        auto=auto,
        distro=distro,
        executor=executor,
    )
    written = []
    if csv:
        writers.write_csv(log, csv)
        written.append(csv)
    if xes:
        writers.write_xes(log, xes, name=source.resolve().name)
        written.append(xes)
    if ocel:
        writers.write_ocel(log, ocel, runs=read_manifests(find_runs(source)))
        written.append(ocel)
    cases = log["case:concept:name"].nunique()
    print(f"{len(log)} events from {cases} run(s) written to {', '.join(map(str, written))}")
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
    executor: str | None = None,
) -> pd.DataFrame:
    """The event log of the recordings at ``source``; an option left ``None`` takes
    :func:`~robotale.eventlog.prepare.prepare`'s default (``executor``: read in this process)."""
    given: dict[str, Any] = {
        "tags": tags,
        "perspectives": (
            None if perspectives is None else [p for p in perspectives.split(",") if p.strip()]
        ),
        "rate": rate,
    }
    return prepare_reporting(
        source,
        tag_fields=TagFields.parse(tag_fields),
        msg_files=msg_files,
        bag_time=bag_time,
        lifecycle=lifecycle,
        actions=actions,
        states=list(state_topics or ()),
        bt_logs=bt_log,
        auto=bool(auto),
        distro=distro,
        executor=executor,
        **{key: value for key, value in given.items() if value is not None},
    )


def prepare_reporting(source: Path, **options: Any) -> pd.DataFrame:
    """:func:`~robotale.eventlog.prepare.prepare` with a progress bar, its warnings (completes
    without a start ...) on stderr as one ``robotale: warning:`` line each."""
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always", PreparationWarning)
        log = prepare(source, progress=True, report=_report, **options)
    for warning in caught:
        if issubclass(warning.category, PreparationWarning):
            print(f"robotale: warning: {warning.message}", file=sys.stderr)
    return log


def _report(text: str) -> None:
    """What the preparation chose (``--auto``), on stderr so that stdout stays the summary."""
    print(f"robotale: {text}", file=sys.stderr)
