"""TALE preparation: rosbag2 recordings -> the canonical multi-perspective event log.

:func:`prepare` is the one function to call. It takes one rosbag2 directory or a folder of them
(a batch of runs: ``runs/agri/run_0001/`` ...), reads each bag's tag topics and the topics of
the chosen perspectives, and enriches the tags (:mod:`robotale.eventlog.enrich`). Every bag is one
case, named after its directory. The result is the DataFrame of :mod:`robotale.eventlog.schema`,
ready for the writers, pm4py or the EKG.

Bags recorded on real ROS 2 robots work too: the tag topics are a glob and the tag message's
field names are configurable (:class:`TagFields`); robotale's ``robotale_msgs/msg/Tag`` is the
default. Tags without a lifecycle are single events, or with ``lifecycle="implicit"``
activities that the robot's next tag ends. Without any tags, what robots already publish says
what they did (:mod:`robotale.eventlog.sources`): action goals, state topics, behaviour-tree
logs; ``auto`` picks those a bag holds.
"""

from __future__ import annotations

import warnings
from collections.abc import Callable, Sequence
from concurrent.futures import Future, as_completed
from dataclasses import dataclass
from fnmatch import fnmatchcase
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np
import pandas as pd
from tqdm import tqdm

from robotale.errors import InputError
from robotale.eventlog import activities, dataset, schema, sources
from robotale.eventlog.bagfiles import RECORDED
from robotale.eventlog.dataset import PartWritten
from robotale.eventlog.enrich import (
    BUILTIN,
    Perspective,
    PreparationWarning,
    enrich,
    parse_perspective,
    robots_without_samples,
)
from robotale.eventlog.interfaces import message_types
from robotale.eventlog.lifecycles import LIFECYCLE_MODES
from robotale.eventlog.runs import (
    find_runs,
    is_recording,
    message_count,
    message_counts,
    robot_type,
    robot_types,
)
from robotale.eventlog.samples import perspective_samples, say_missing_samples, warn_missing_samples
from robotale.eventlog.sources import Sources
from robotale.eventlog.tagrows import (
    TagFields,
    robot_of_topics,
    tag_columns,
    topic_rows,
    warn_foreign,
)
from robotale.eventlog.typesys import check_distro
from robotale.executors import open_executor, parse_executor, stop_all, worker_lost
from robotale.fame_runtime.manifest import read_manifests
from robotale.storage import Place, place

if TYPE_CHECKING:
    from robotale.eventlog.rosbag import Bag


TAG_TOPICS = "/*/tag"
DEFAULT_PERSPECTIVES = ("odom", "battery")


@dataclass(frozen=True)
class _Reading:
    """What every bag of a preparation is read for."""

    tags: str
    tag_fields: TagFields
    lifecycle: str | None
    sources: Sources
    auto: bool
    perspectives: Sequence[Perspective]
    bag_time: bool
    #: the robot of activities on topics without a namespace (None: the bag says)
    robot: str | None = None


@dataclass(frozen=True)
class Job:
    """A preparation's options, checked: what a worker needs to prepare a run on its own."""

    reading: _Reading
    msg_files: tuple[Path, ...]
    #: the distribution named (None: the one each bag names)
    distro: str | None
    rate: float


def prepare(
    source: str | Path,
    *,
    progress: bool = False,
    report: Callable[[str], None] | None = None,
    executor: str | None = None,
    skip_bad: Callable[[Path, str], None] | None = None,
    **options: Any,
) -> pd.DataFrame:
    """The multi-perspective event log of a rosbag2 directory or of a folder of them.

    ``options`` are those of :func:`preparation`: ``tags`` is the glob of the tag topics
    (default :data:`TAG_TOPICS`); ``perspectives`` are built-in names (``odom``,
    ``battery``), ``NAME=TOPIC_GLOB:FIELD`` strings or :class:`Perspective` objects; ``rate`` is
    the number of ``inprogress`` events per second of an activity (0: none); ``msg_files`` are
    ``.msg`` / ``.idl`` files (or folders) for types the bags do not define; ``bag_time`` uses
    recording times instead of message stamps; ``progress`` shows a bar on stderr.

    ``lifecycle`` is one of :data:`LIFECYCLE_MODES` (default: ``explicit`` when the tags have a
    lifecycle field, else ``events``). Activities also come from ``actions`` (a glob of
    ``<action>/_action/status`` topics), ``states`` (``GLOB[:FIELD]`` state topics) and
    ``bt_logs`` (a glob of behaviour-tree logs); ``auto`` adds whatever of those each bag
    holds and tells ``report`` what it chose. ``distro`` names the ROS 2 distribution whose
    standard types fill in those a bag does not define. ``robot`` names the robot of tags and
    activities on topics without a namespace (else the bag's only namespace, else ``robot``,
    with a warning).

    ``executor`` (``local[:N]``, ``dask://HOST:PORT``; see :mod:`robotale.executors`) reads
    the runs in parallel, each run on its own (no reading crosses runs), with the same log as
    reading them here one after the other.

    ``skip_bad`` hears of each run that cannot be read (the run, why), which is then left
    out; without it such a run stops the preparation.
    """
    job = preparation(**options)
    reading, msg_files, distro, rate = job.reading, job.msg_files, job.distro, job.rate
    chosen = list(reading.perspectives)
    runs = find_runs(Path(source))
    if executor is not None:
        told: set[str] = set()
        read = _read_in_parallel(
            runs, reading, msg_files, distro, executor, progress, _once(report, told), skip_bad
        )
    else:
        read = _read_here(runs, reading, msg_files, distro, progress, report, skip_bad)
    runs = [run for run, part in zip(runs, read, strict=True) if part is not None]
    parts = [part for part in read if part is not None]
    if not parts:
        raise InputError(_none_read(source))
    tag_rows = pd.concat([tag_part for tag_part, _ in parts], ignore_index=True)
    if tag_rows.empty:
        raise InputError(_nothing_found(source, reading))
    samples = {
        p.name: pd.concat([sample_parts[p.name] for _, sample_parts in parts], ignore_index=True)
        for p in chosen
    }
    warn_missing_samples(tag_rows, samples, chosen)
    tag_rows[schema.ROBOT_TYPE] = robot_types(tag_rows, read_manifests(runs))
    log = enrich(tag_rows, samples, rate=rate)
    return _canonical(log, chosen)


def preparation(
    *,
    tags: str = TAG_TOPICS,
    tag_fields: TagFields | None = None,
    perspectives: Sequence[str | Perspective] = DEFAULT_PERSPECTIVES,
    rate: float = 1.0,
    msg_files: Sequence[str | Path] = (),
    bag_time: bool = False,
    lifecycle: str | None = None,
    actions: str | None = None,
    states: Sequence[str] = (),
    bt_logs: str | None = None,
    auto: bool = False,
    distro: str | None = None,
    robot: str | None = None,
) -> Job:
    """The options of :func:`prepare` and :func:`prepare_dataset`, checked: what every bag is
    read for and how its events are enriched."""
    chosen = [p if isinstance(p, Perspective) else parse_perspective(p) for p in perspectives]
    if lifecycle is not None and lifecycle not in LIFECYCLE_MODES:
        raise InputError(f"Unknown lifecycle mode {lifecycle!r}: use {', '.join(LIFECYCLE_MODES)}.")
    if rate < 0:
        raise InputError(f"The inprogress rate must be 0 or more per second, not {rate}.")
    sources = Sources(actions, tuple(states), bt_logs)
    if robot is not None and not robot.strip():
        raise InputError("--robot names the robot of topics without a namespace: give a name.")
    reading = _Reading(
        tags, tag_fields or TagFields(), lifecycle, sources, auto, chosen, bag_time,
        robot and robot.strip(),
    )  # fmt: skip
    return Job(reading, tuple(Path(p).resolve() for p in msg_files), check_distro(distro), rate)


def _read_here(
    runs: Sequence[Path],
    reading: _Reading,
    msg_files: Sequence[str | Path],
    distro: str | None,
    progress: bool,
    report: Callable[[str], None] | None,
    skip_bad: Callable[[Path, str], None] | None = None,
) -> list[tuple[pd.DataFrame, dict[str, pd.DataFrame]] | None]:
    """Every run read in this process, with a progress bar over their messages; None for a
    run that could not be read when ``skip_bad`` was told of it."""
    # the bag reader (rosbags, MCAP, zstandard) only when a recording is read: a CSV's
    # preparation shares this module and was paid a quarter of its import time for it
    from robotale.eventlog.rosbag import Bag

    extra_types = message_types([Path(p) for p in msg_files])
    globs = [reading.tags, *(glob for p in reading.perspectives for glob in p.topic.split("|"))]
    with tqdm(
        total=sum(message_count(run, globs) for run in runs),
        unit="msg",
        desc="prepare",
        disable=not progress,
        leave=False,
    ) as bar:
        told: set[str] = set()
        read: list[tuple[pd.DataFrame, dict[str, pd.DataFrame]] | None] = []
        for run in runs:
            try:
                read.append(
                    _read_run(Bag(run, extra_types, distro), reading, bar, _once(report, told))
                )
            except InputError as error:
                if skip_bad is None:
                    raise
                skip_bad(run, str(error))
                read.append(None)
        return read


def _read_in_parallel(
    runs: Sequence[Path],
    reading: _Reading,
    msg_files: Sequence[str | Path],
    distro: str | None,
    executor: str,
    progress: bool,
    say: Callable[[str], None],
    skip_bad: Callable[[Path, str], None] | None = None,
) -> list[tuple[pd.DataFrame, dict[str, pd.DataFrame]] | None]:
    """Every run read by the executor's workers, a progress bar over runs as they finish;
    what the workers warned and reported is said here, run by run in order. None for a run
    that could not be read when ``skip_bad`` was told of it."""
    files = tuple(Path(p).resolve() for p in msg_files)
    skipping = skip_bad is not None
    with tqdm(
        total=len(runs), unit="run", desc="prepare", disable=not progress, leave=False
    ) as bar:
        read = _on_executor(
            executor, runs, bar, "reading", _read_alone, reading, files, distro, skipping
        )
    done = dict(zip(runs, read, strict=True))
    parts: list[tuple[pd.DataFrame, dict[str, pd.DataFrame]] | None] = []
    for run in runs:
        for category, message in done[run].warned:
            warnings.warn(message, category, stacklevel=2)
        for text in done[run].reported:
            say(text)
        if done[run].unreadable and skip_bad is not None:
            skip_bad(run, done[run].unreadable)
            parts.append(None)
        else:
            parts.append((done[run].tag_rows, done[run].samples))
    return parts


@dataclass
class _RunRead:
    """One run as a worker read it, with what it warned and reported on the way; or why it
    could not be read (``unreadable``: the batch skips it)."""

    tag_rows: pd.DataFrame
    samples: dict[str, pd.DataFrame]
    warned: list[tuple[type[PreparationWarning], str]]
    reported: list[str]
    unreadable: str = ""


def _read_alone(
    run: Path,
    reading: _Reading,
    msg_files: Sequence[Path],
    distro: str | None,
    skipping: bool = False,
) -> _RunRead:
    """:func:`_read_run` in a worker process: warnings and reports are kept to be said by
    the process that asked, as they would not reach its terminal from here. ``skipping``: a
    run that cannot be read is returned with why, for the batch to skip, instead of raised."""
    # the bag reader (rosbags, MCAP, zstandard) only when a recording is read: a CSV's
    # preparation shares this module and was paid a quarter of its import time for it
    from robotale.eventlog.rosbag import Bag

    reported: list[str] = []
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always", PreparationWarning)
        try:
            bag = Bag(run, message_types(list(msg_files)), distro)
            tag_rows, samples = _read_run(bag, reading, None, reported.append)
        except InputError as error:
            if not skipping:
                raise
            return _RunRead(pd.DataFrame(), {}, [], [], unreadable=str(error))
    warned = [
        (w.category, str(w.message)) for w in caught if issubclass(w.category, PreparationWarning)
    ]
    return _RunRead(tag_rows, samples, warned, reported)


# -- a Parquet dataset, written run by run ------------------------------------------------------


@dataclass
class _RunPrepared:
    """One run prepared and written as its part (None: the run has no activities), with its
    samples per perspective (how many, which robots had none) and what it warned and
    reported on the way."""

    part: PartWritten | None
    samples: dict[str, int]
    unsampled: dict[str, list[str]]
    warned: list[tuple[type[PreparationWarning], str]]
    reported: list[str]
    #: why the run could not be read ("" when it was): the batch skips it
    unreadable: str = ""


def prepare_dataset(
    source: str | Path,
    out: str | Path,
    *,
    progress: bool = False,
    report: Callable[[str], None] | None = None,
    executor: str | None = None,
    skip_bad: Callable[[Path, str], None] | None = None,
    **options: Any,
) -> dict[str, Any]:
    """The event log of :func:`prepare`, written as a Parquet dataset partitioned by case at
    ``out`` (a path or an fsspec URL; see :mod:`robotale.eventlog.dataset`); returns its
    manifest.

    Each run is prepared and written by whoever reads it: this process, or with ``executor``
    a worker, so the events of a batch never travel to this process. Its rows are those
    :func:`prepare` gives the run (enrichment works within a case). A failure removes what
    was written. ``skip_bad`` hears of each run that cannot be read (the run, why), which is
    then left out of the dataset; without it such a run stops the preparation.
    """
    job = preparation(**options)
    reading = job.reading
    runs = find_runs(Path(source))
    target = place(out)
    dataset.begin(target, str(source))
    try:
        done = _runs_written(runs, job, target, executor, progress, skip_bad is not None)
        told: set[str] = set()
        say = _once(report, told)
        for path, run in zip(runs, done, strict=True):
            for category, message in run.warned:
                warnings.warn(message, category, stacklevel=2)
            for text in run.reported:
                say(text)
            if run.unreadable and skip_bad is not None:
                skip_bad(path, run.unreadable)
        if all(run.unreadable for run in done):
            raise InputError(_none_read(source))
        done = [run for run in done if not run.unreadable]
        parts = [run.part for run in done if run.part is not None]
        if not parts:
            raise InputError(_nothing_found(source, reading))
        chosen = reading.perspectives
        say_missing_samples(
            {p.name: sum(run.samples[p.name] for run in done) for p in chosen},
            {p.name: [r for run in done for r in run.unsampled[p.name]] for p in chosen},
            chosen,
        )
        return dataset.finish(target, parts, str(source))
    except BaseException:
        dataset.abandon(target)
        raise


def _runs_written(
    runs: Sequence[Path],
    job: Job,
    target: Place,
    executor: str | None,
    progress: bool,
    skipping: bool = False,
) -> list[_RunPrepared]:
    """Every run prepared into ``target``, here or by the executor's workers, in run order;
    ``skipping``: a run that cannot be read comes back with why instead of stopping them."""
    bar = tqdm(total=len(runs), unit="run", desc="prepare", disable=not progress, leave=False)
    with bar:
        if executor is None:
            written = []
            for run in runs:
                written.append(_prepare_into(run, job, target, skipping))
                bar.update()
            return written
        return _on_executor(executor, runs, bar, "preparing", _prepare_into, job, target, skipping)


def _on_executor(
    executor: str,
    runs: Sequence[Path],
    bar: tqdm,
    doing: str,
    task: Callable[..., Any],
    *arguments: Any,
) -> list[Any]:
    """``task(run, *arguments)`` for every run on the executor's workers (each run given as
    an absolute path), the bar counting runs as they finish; the results in run order."""
    done: dict[Path, Any] = {}
    with open_executor(parse_executor(executor), len(runs)) as (pool, _):
        futures = {pool.submit(task, run.resolve(), *arguments): run for run in runs}
        try:
            for future in as_completed(futures):
                done[futures[future]] = _result(future, futures[future], doing)
                bar.update()
        except BaseException as error:
            stop_all(futures, error)
            raise
    return [done[run] for run in runs]


def _result(future: Future[Any], run: Path, doing: str) -> Any:
    """What ``future`` computed for ``run``; a worker that died is said as one sentence."""
    try:
        return future.result()
    except Exception as error:
        if worker_lost(error):
            raise InputError(f"{run}: the worker process {doing} it died") from None
        raise


def _prepare_into(run: Path, job: Job, target: Place, skipping: bool = False) -> _RunPrepared:
    """One run read, enriched and written as its part of ``target`` (in a worker process or
    here); its warnings and reports are kept to be said by the process that asked.
    ``skipping``: a run that cannot be read is returned with why (nothing of it written)
    instead of raised; a failure to write stays one."""
    # the bag reader (rosbags, MCAP, zstandard) only when a recording is read: a CSV's
    # preparation shares this module and was paid a quarter of its import time for it
    from robotale.eventlog.rosbag import Bag

    reported: list[str] = []
    perspectives = job.reading.perspectives
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always", PreparationWarning)
        try:
            bag = Bag(run, message_types(list(job.msg_files)), job.distro)
            tag_rows, samples = _read_run(bag, job.reading, None, reported.append)
        except InputError as error:
            if not skipping:
                raise
            return _RunPrepared(None, {}, {}, [], [], unreadable=str(error))
        part = None
        if not tag_rows.empty:
            tag_rows[schema.ROBOT_TYPE] = robot_types(tag_rows, read_manifests([run]))
            log = _canonical(enrich(tag_rows, samples, rate=job.rate), perspectives)
            part = dataset.write_part(log, target)
    warned = [
        (w.category, str(w.message)) for w in caught if issubclass(w.category, PreparationWarning)
    ]
    return _RunPrepared(
        part,
        {p.name: len(samples[p.name]) for p in perspectives},
        {p.name: robots_without_samples(tag_rows, samples[p.name]) for p in perspectives},
        warned,
        reported,
    )


def _none_read(source: str | Path) -> str:
    return f"None of the runs of {source} could be read."


def _read_run(
    opened: Bag, reading: _Reading, bar: tqdm | None, report: Callable[[str], None]
) -> tuple[pd.DataFrame, dict[str, pd.DataFrame]]:
    run = opened.path
    with opened as bag:
        tag_topics = [t for t in bag.topics if fnmatchcase(t, reading.tags)]
        chosen = _sources(bag, reading, report)
        if not tag_topics and not chosen:
            raise InputError(
                f"{run} has no tag topic matching {reading.tags!r}; its topics are "
                f"{', '.join(bag.topics) or 'none'} (name the tag topics with --tags)."
            )
        columns = {t: tag_columns(bag, t, reading.tag_fields) for t in tag_topics}
        for topic, wanted in sources.columns(bag, chosen).items():
            columns[topic] = {**columns.get(topic, {}), **wanted}
        sample_topics = {
            p.name: [t for t in bag.topics if p.matches(t) and t not in columns]
            for p in reading.perspectives
        }
        for p in reading.perspectives:
            for topic in sample_topics[p.name]:
                columns[topic] = {**columns.get(topic, {}), **p.columns}
        tables = bag.tables(columns, bag_time=reading.bag_time, recorded=True, progress=bar)
        recorded = {topic: table.pop(RECORDED).to_numpy() for topic, table in tables.items()}
        tables = {topic: sources.numbered(table) for topic, table in tables.items()}
        end = pd.Timestamp(max(bag.reader.end_time - 1, 0), unit="ns", tz="UTC")
        warn_foreign(bag, columns)
        robot_of = robot_of_topics(bag, reading.robot)
        parts = [
            topic_rows(tables[t], t, run, reading.tag_fields, reading.lifecycle, robot_of)
            for t in tag_topics
        ]
        parts += sources.activity_rows(bag, tables, chosen, run.name, end, robot_of)
    tag_rows = activities.in_order(parts, recorded)
    if reading.lifecycle == "implicit" and tag_topics:
        tag_rows = activities.implicit(tag_rows, {run.name: end}, tag_topics)
    tag_rows = tag_rows.drop(columns=activities.SEQUENCE)
    robots = sorted(set(tag_rows[schema.ROBOT]))
    samples = {
        p.name: perspective_samples(run, [(t, tables[t]) for t in sample_topics[p.name]], p, robots)
        for p in reading.perspectives
    }
    return tag_rows, samples


def _sources(bag: Bag, reading: _Reading, report: Callable[[str], None]) -> Sources:
    """The non-tag sources for a bag: those asked for, and with ``auto`` those it holds."""
    if not reading.auto:
        return reading.sources
    found = sources.propose(bag)
    chosen = Sources(
        reading.sources.actions or found.actions,
        tuple(dict.fromkeys([*reading.sources.states, *found.states])),
        reading.sources.bt_logs or found.bt_logs,
    )
    tags = [t for t, n in bag.reader.topics.items() if fnmatchcase(t, reading.tags) and n.msgcount]
    said = [f"--tags {reading.tags}"] if tags else []
    unread = [
        f"{t} ({kind})" for t, kind in bag.topics.items() if kind not in bag.typestore.fielddefs
    ]
    more = ", ..." if len(unread) > 3 else ""
    skipped = (
        f" ({len(unread)} topic(s) not looked into, their types having no definition: "
        f"{', '.join(unread[:3])}{more}; give them with --msg)"
        if unread
        else ""
    )
    report(
        f"{bag.name}: activities from "
        + (", ".join(said + chosen.describe()) or "nothing (no tags, actions, states or BT logs)")
        + skipped
    )
    return chosen


def _once(report: Callable[[str], None] | None, told: set[str]) -> Callable[[str], None]:
    """``report`` that says each choice once (a batch's runs usually all choose the same)."""

    def say(text: str) -> None:
        key = text.partition(": ")[2]
        if report is not None and key not in told:
            told.add(key)
            with tqdm.external_write_mode():  # on a line of its own, not after the bar
                report(text)

    return say


def _nothing_found(source: Path | str, reading: _Reading) -> str:
    """Why no activity came out, from what the bags hold (their metadata's counts)."""
    counts: dict[str, int] = {}
    for run in find_runs(Path(source)):
        for topic, count in message_counts(run, [reading.tags]).items():
            counts[topic] = counts.get(topic, 0) + count
    tags = sum(counts.values())
    if tags:
        held = (
            f"its topics matching {reading.tags!r} hold {tags} message(s) whose activity field "
            f"({reading.tag_fields.activity!r}) is empty; name the field that holds the activity "
            "with --tag-field activity=FIELD"
        )
    elif counts:
        held = f"its topics matching {reading.tags!r} ({', '.join(sorted(counts))}) hold no message"
    else:
        held = f"no topic matches {reading.tags!r} (name the tag topics with --tags)"
    if reading.sources or reading.auto:
        return (
            f"{source} has no activities: {held}, and its action, state and behaviour-tree "
            "topics asked for hold none (with --auto, what it looked into is said above)."
        )
    return f"{source} has no tags: {held}."


def tags_log(tag_rows: pd.DataFrame) -> pd.DataFrame:
    """The log ``prepare`` makes, with its defaults, of tags heard with no recording around
    them (a live run's): the same enrichment (``inprogress`` events at the default rate) and
    columns, its perspectives' columns empty, since no samples were read."""
    job = preparation()
    return _canonical(enrich(tag_rows, {}, rate=job.rate), job.reading.perspectives)


def _canonical(log: pd.DataFrame, perspectives: Sequence[Perspective]) -> pd.DataFrame:
    """Known columns in the documented order, every perspective column present, event ids."""
    for column in [c for p in perspectives for c in p.columns]:
        if column not in log:
            log[column] = np.nan
    for column in (schema.MSG_ID, schema.MSG_ROLE, schema.MSG_PAYLOAD):
        if column not in log:
            log[column] = None
    # nanoseconds, as the bag records them (every written format but XES keeps them)
    log[schema.TIMESTAMP] = log[schema.TIMESTAMP].dt.as_unit("ns")
    position = log.groupby(schema.CASE, sort=False).cumcount().astype(str)
    log[schema.EVENT_ID] = log[schema.CASE].astype(str) + ":" + position
    known = [c for c in schema.CSV_NAMES if c in log]
    return log[known + [c for c in log if c not in schema.CSV_NAMES]]


__all__ = [
    "BUILTIN",
    "DEFAULT_PERSPECTIVES",
    "LIFECYCLE_MODES",
    "TAG_TOPICS",
    "TagFields",
    "find_runs",
    "is_recording",
    "preparation",
    "prepare",
    "prepare_dataset",
    "robot_type",
    "tags_log",
]
