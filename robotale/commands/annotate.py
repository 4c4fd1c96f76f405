"""``robotale annotate``: each recording copied as MCAP with what robotale mined from it, for
the bag viewers robot developers already use (Foxglove, Lichtblick, PlotJuggler).

The log is prepared as ``prepare`` prepares it (the same options); each run's copy gets its
robots' activities as state topics and, as log entries, its message exchanges and findings:
lost messages, the activity instances behind a bottleneck, and with ``--model`` the
deviations from the BPMN model (:mod:`robotale.eventlog.annotated`).
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

from robotale.discovery.conformance import check_conformance
from robotale.enhancement.bottlenecks import find_bottlenecks
from robotale.enhancement.communication import message_table
from robotale.errors import InputError
from robotale.eventlog import schema
from robotale.eventlog.annotated import INFO, WARN, Entry, activity_states, write_annotated
from robotale.eventlog.enrich import pair_activities
from robotale.eventlog.interfaces import message_types
from robotale.eventlog.options import PrepareOptions
from robotale.eventlog.prepare import find_runs
from robotale.eventlog.preparing import prepare_recordings
from robotale.eventlog.rosbag import Bag
from robotale.eventlog.typesys import check_distro

CASE, TIME, ROBOT, ACTIVITY = schema.CASE, schema.TIMESTAMP, schema.ROBOT, schema.ACTIVITY


def annotate_command(
    source: Path,
    out: Path,
    model: Path | None = None,
    skip_bad: bool = False,
    **options: Any,
) -> int:
    """Write ``out/<run>/`` for every run of ``source``: an MCAP rosbag2 copy of the run with
    the added topics; ``options`` are the fields of
    :class:`~robotale.eventlog.options.PrepareOptions`. With ``skip_bad`` a run that
    cannot be read is named and left out, as ``prepare --skip-bad`` does."""
    runs = find_runs(source)
    taken = [out / run.name for run in runs if (out / run.name).exists()]
    if taken:
        raise InputError(f"{taken[0]} exists already: give --out a folder without it.")
    if model is not None and not Path(model).is_file():
        raise InputError(f"The model {model} does not exist.")
    # the added topics need activities and messages only: no perspective (the odometry a
    # bag is mostly made of) is read unless one is asked for
    preparation = PrepareOptions.given({"perspectives": "", **options, "rate": 0.0})
    msg_files, distro = preparation.msg_files, preparation.distro
    skipped: list[Path] | None = [] if skip_bad else None
    log = prepare_recordings(source, preparation, skipped=skipped)
    if skipped:
        runs = [run for run in runs if run not in skipped]
    names = sorted(log[ACTIVITY].dropna().astype(str).unique())
    extra = message_types([Path(p) for p in msg_files])
    slow = bottleneck_instances(log)  # ranked over every run: one run has no baseline
    for run in runs:
        events = log[log[CASE] == run.name].reset_index(drop=True)
        entries = findings(events, model, slow.get(run.name, []))
        with Bag(run, extra, check_distro(distro)) as bag:
            added = write_annotated(bag, out / run.name, activity_states(events), entries, names)
        topics = len(added)
        print(
            f"{out / run.name}: {run.name} copied with {topics} added topic(s), "
            f"{sum(added.values())} added message(s)"
        )
    return 0


def findings(events: pd.DataFrame, model: Path | None, slow: list[Entry]) -> list[Entry]:
    """The log entries of one run: its message exchanges, lost messages, its bottleneck
    instances ``slow`` and (with ``model``) deviations, in time order."""
    entries = exchanges(events) + slow
    if model is not None:
        entries += deviations(events, model)
    return sorted(entries, key=lambda e: e.time)


def _nanos(time: pd.Timestamp) -> int:
    return int(pd.Timestamp(time).as_unit("ns").value)


def exchanges(events: pd.DataFrame) -> list[Entry]:
    """Each message's send and receive; a message nobody received is a lost message."""
    messages = message_table(events)
    entries = []
    for row in messages.to_dict("records") if not messages.empty else []:
        kind, ident = row.get("message_type") or "", row.get(schema.MSG_ID)
        if pd.notna(row.get("sent_at")):
            entries.append(
                Entry(_nanos(row["sent_at"]), INFO, "robotale.messages",
                      f"{row.get('sender')} sent message {ident} ({kind})")
            )  # fmt: skip
        if pd.notna(row.get("received_at")):
            entries.append(
                Entry(_nanos(row["received_at"]), INFO, "robotale.messages",
                      f"{row.get('receiver')} received message {ident} ({kind})")
            )  # fmt: skip
        if row.get("lost"):
            entries.append(
                Entry(_nanos(row["sent_at"]), WARN, "robotale.findings",
                      f"lost message: {ident} ({kind}) sent by {row.get('sender')} was never "
                      "received")
            )  # fmt: skip
    return entries


def bottleneck_instances(log: pd.DataFrame) -> dict[str, list[Entry]]:
    """For each bottleneck of the log that names an activity, the instances of that activity
    (of that robot) that took longer than its median over the log, each an entry at its end;
    by run."""
    found = find_bottlenecks(log)
    ranking = found.tables.get("bottlenecks") if found.tables else None
    if ranking is None or ranking.empty:
        return {}
    starts, ends, _ = pair_activities(log)
    times = log[TIME].to_numpy("datetime64[ns]").view(np.int64)
    instances = pd.DataFrame(
        {
            "case": log[CASE].to_numpy()[starts],
            "activity": log[ACTIVITY].to_numpy()[starts],
            "robot": log[ROBOT].to_numpy()[starts] if ROBOT in log else None,
            "start": times[starts],
            "end": times[ends],
        }
    )
    instances["seconds"] = (instances["end"] - instances["start"]) / 1e9
    entries: dict[str, list[Entry]] = {}
    by_activity = dict(tuple(instances.groupby("activity", sort=False)))
    for row in ranking.to_dict("records"):
        activity, robot = row.get("activity"), row.get("robot")
        if not isinstance(activity, str) or activity not in by_activity:
            continue
        mine = by_activity[activity]
        if isinstance(robot, str):
            mine = mine[mine["robot"] == robot]
        median = mine["seconds"].median()
        for slow in mine[mine["seconds"] > median].to_dict("records"):
            entries.setdefault(slow["case"], []).append(
                Entry(int(slow["end"]), WARN, "robotale.findings",
                      f"bottleneck instance: {activity} of {slow['robot']} took "
                      f"{slow['seconds']:.3f} s (median {median:.3f} s); {row['explanation']}")
            )  # fmt: skip
    return entries


def deviations(events: pd.DataFrame, model: Path) -> list[Entry]:
    """The run's deviations from ``model``: an activity the model does not expect, at each of
    its events; one the model expects and the robot did not do, at the robot's last event."""
    report = check_conformance(events, model)
    entries = []
    for row in report.deviations.to_dict("records"):
        robot, activity = row["robot"], row["activity"]
        mine = events[events[ROBOT].astype(str) == str(robot)]
        if mine.empty:
            continue
        if row["kind"] == "missing":
            entries.append(
                Entry(_nanos(mine[TIME].iloc[-1]), WARN, "robotale.findings",
                      f"deviation: the model expects {activity} of {robot}, which did not "
                      "happen")
            )  # fmt: skip
            continue
        doing = mine[mine[ACTIVITY].astype(str) == str(activity)]
        doing = doing[doing[schema.LIFECYCLE] != schema.NONE]
        starts = doing[doing[schema.LIFECYCLE] == schema.START]
        for time in (starts if not starts.empty else doing)[TIME]:
            entries.append(
                Entry(_nanos(time), WARN, "robotale.findings",
                      f"deviation: {activity} of {robot} is not where the model allows it")
            )  # fmt: skip
    return entries
