"""From an uploaded file to a log in Neo4j, in the two steps of thesis figure 7.3.

1. :func:`read_upload` turns the upload into the canonical event log (a CSV, XES or OCEL 2.0
   log with ``robotale.eventlog.readers``, an OCEL log's objects kept beside it; a zipped
   folder of rosbag2 recordings with ``robotale.eventlog.prepare``) and keeps it in memory as
   a :class:`Pending` log.
2. The user picks the columns to store as event properties and those that are entities;
   :func:`ingest` stores the log with :func:`robotale.ekg.build.build_ekg` and deletes the upload.
"""

from __future__ import annotations

import shutil
import threading
import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import pandas as pd
from neo4j import Driver

from robotale.ekg.build import build_ekg
from robotale.ekg.disk_space import check_space
from robotale.ekg.keys import DEFAULT_ENTITIES, built_keys
from robotale.ekg.logs import stored_events
from robotale.errors import InputError, RobotaleError
from robotale.eventlog import schema
from robotale.eventlog.objects import Objects
from robotale.eventlog.prepare import find_runs, prepare
from robotale.eventlog.readers import read_with_objects
from robotale.eventlog.reading import format_reading
from robotale.fame_runtime.manifest import read_manifests
from robotale.results.logdata import LogData, first_key
from robotale.results.site import keep_sites, run_sites
from robotale.sim import scenarios
from robotale.webapp import uploads
from robotale.webapp.jobs import Job
from robotale.webapp.model_store import ModelStore
from robotale.webapp.opened_run import opened_run

#: columns every stored log keeps, whatever the user unticks
ALWAYS_STORED = (*schema.REQUIRED, schema.LIFECYCLE)
#: a zipped bag folder may unpack to this many times the upload limit
UNPACK_FACTOR = 20


@dataclass
class Pending:
    upload: uploads.Upload
    #: CSV / XES column -> canonical field, for logs whose columns have other names
    mapping: dict[str, str] = field(default_factory=dict)
    log: pd.DataFrame | None = None
    model_id: str | None = None
    created: float = field(default_factory=time.time)
    #: without a case column, a new case after every pause this long ("1h", "90s")
    case_gap: str | None = None
    #: how the file was read (``format_reading``), for the column-choice page
    reading: str = ""
    #: the case gap the column-choice page offers (a log of several days without cases)
    session_gap: str | None = None
    #: the simulated runs' sites (field, bases, objects) by case, for the Mission page's map
    sites: dict[str, Any] = field(default_factory=dict)
    #: an object-centric log's objects (attributes, qualifiers, relations), stored with it
    objects: Objects | None = None


@dataclass(frozen=True)
class Column:
    """One column of a pending log as the column-choice form shows it."""

    name: str  # the short name, also the Event property it becomes
    required: bool
    store: bool
    entity: bool
    distinct: int
    examples: list[str]


class PendingLogs:
    """Uploads read into logs, waiting for the user's column choice (one process, in memory)."""

    def __init__(self) -> None:
        self._items: dict[str, Pending] = {}
        self._lock = threading.Lock()

    def add(
        self, upload: uploads.Upload, mapping: dict[str, str], case_gap: str | None = None
    ) -> Pending:
        pending = Pending(upload, mapping, case_gap=case_gap)
        with self._lock:
            self._forget_stale()
            self._items[upload.token] = pending
        return pending

    def _forget_stale(self) -> None:
        # an upload read but never stored: its file and its log go after a day
        limit = time.time() - uploads.STALE_AFTER
        for token in [t for t, p in self._items.items() if p.created < limit]:
            uploads.discard(self._items.pop(token).upload)

    def get(self, token: str) -> Pending:
        with self._lock:
            pending = self._items.get(token)
        if pending is None or pending.log is None:
            raise InputError("That upload is gone (it was ingested or is too old): upload again.")
        return pending

    def pop(self, token: str) -> Pending | None:
        with self._lock:
            return self._items.pop(token, None)


def read_upload(pending: Pending, limit_bytes: int, models: ModelStore, job: Job) -> None:
    """Read ``pending.upload`` into ``pending.log``; a model inside a zip is stored too."""
    upload = pending.upload
    job.step("reading " + upload.filename)
    try:
        if upload.kind == "zip":
            pending.log, pending.model_id, pending.sites = _read_bags(
                upload, limit_bytes, models, job
            )
        else:
            pending.log, reading, pending.objects = read_with_objects(
                upload.path, pending.mapping, case_gap=pending.case_gap
            )
            # the reading names our stored copy; the user knows the file by its own name
            pending.reading = format_reading(reading).replace(str(upload.path), upload.filename)
            pending.session_gap = reading.session_gap
    except RobotaleError as error:
        # The message names our stored copy; the user knows the file by its own name.
        raise type(error)(str(error).replace(str(upload.path), repr(upload.filename))) from None
    finally:
        if pending.log is None:
            uploads.discard(upload)
    if pending.log.empty:
        uploads.discard(upload)
        raise InputError(f"{upload.filename!r} holds no events.")
    job.step("read", len(pending.log), len(pending.log))


def _read_bags(
    upload: uploads.Upload, limit_bytes: int, models: ModelStore, job: Job
) -> tuple[pd.DataFrame, str | None, dict[str, Any]]:
    folder = uploads.unpack(upload, limit_bytes * UNPACK_FACTOR)
    try:
        job.step("preparing the recordings")
        root = bag_root(folder)
        log = prepare(root)
        model = next(iter(sorted(folder.rglob("*.bpmn"))), None) or shipped_model(root)
        model_id = models.add(model.read_bytes(), model.name).id if model else None
        return log, model_id, run_sites(root)
    finally:
        shutil.rmtree(folder, ignore_errors=True)


def shipped_model(root: Path) -> Path | None:
    """The mission model of the shipped scenario the recordings' manifests name, if one."""
    names = {m.get("scenario") for m in read_manifests(find_runs(root)).values()}
    if len(names) != 1 or (name := names.pop()) not in scenarios.names():
        return None
    return scenarios.FOLDER / f"{name}.bpmn"


def bag_root(folder: Path) -> Path:
    """The folder to prepare: the unpacked one, or the single folder a zip wraps its bags in."""
    while not (folder / "metadata.yaml").is_file():
        children = [c for c in folder.iterdir() if c.is_dir() and not c.name.startswith(".")]
        if any((c / "metadata.yaml").is_file() for c in children) or len(children) != 1:
            break
        folder = children[0]
    return folder


def columns(log: pd.DataFrame, objects: Objects | None = None) -> list[Column]:
    """The log's columns with the default choice: store everything; the default entity
    columns (robot and msg_id, as in thesis figure 7.3), or an object-centric log's object
    types, are entities where the log has them."""
    defaults = objects.entity_types if objects is not None else DEFAULT_ENTITIES
    found = []
    for canonical in log.columns:
        name = schema.CSV_NAMES.get(canonical, canonical)
        values = log[canonical].dropna()
        shown = values.astype(str).drop_duplicates().head(3).tolist()
        found.append(
            Column(
                name=name,
                required=canonical in ALWAYS_STORED,
                store=True,
                entity=name in defaults and values.nunique() > 0,
                distinct=int(values.nunique()),
                examples=shown,
            )
        )
    return found


def chosen_log(
    log: pd.DataFrame, store: list[str], entities: list[str], objects: Objects | None = None
) -> pd.DataFrame:
    """The log with only the columns to store (required ones and entities always kept; the
    event ids too where ``objects`` relate events to objects by them)."""
    short = {schema.CSV_NAMES.get(c, c): c for c in log.columns}
    unknown = [name for name in [*store, *entities] if name not in short]
    if unknown:
        raise InputError(f"The log has no column {unknown[0]!r}.")
    if not entities:
        raise InputError("Tick at least one entity column (robot, for instance).")
    always = (*ALWAYS_STORED, schema.EVENT_ID) if objects is not None else ALWAYS_STORED
    keep = {short[n] for n in [*store, *entities]} | {c for c in always if c in log}
    return log[[c for c in log.columns if c in keep]]


def ingest(
    driver: Driver,
    pending: Pending,
    name: str,
    entities: list[str],
    replace: bool,
    models: ModelStore,
    logs: LogData,
    job: Job,
) -> dict[str, Any]:
    """Store the pending log as ``name``; the upload is deleted whatever happens."""
    log = pending.log
    if log is None:
        raise InputError("That upload has not been read yet: wait for it, then choose again.")
    try:
        check_space(driver, log, name, entities, len(built_keys(entities)))
        job.step("writing to Neo4j", 0, len(log))
        with _ProgressWatch(driver, name, job, enabled=not replace):
            summary = build_ekg(
                driver,
                log,
                name,
                entities=entities,
                aggregate=built_keys(entities),
                replace=replace,
                source=pending.upload.filename,
                progress=False,
                objects=pending.objects,
            )
    finally:
        uploads.discard(pending.upload)
    if pending.model_id:
        models.link(name, pending.model_id)
    keep_sites(driver, name, pending.sites)
    job.step("drawing its process")
    logs.forget(name)
    logs.class_graph(driver, name, first_key(entities))  # the Discover page's first view, ready
    result = {"log": summary.log, "events": summary.events, "seconds": round(summary.seconds, 2)}
    return {**result, **opened_run(pending.upload.kind, log)}


class _ProgressWatch:
    """While a log is built, counts its events in Neo4j to report how far the build has come."""

    def __init__(self, driver: Driver, log: str, job: Job, enabled: bool) -> None:
        self.driver, self.log, self.job, self.enabled = driver, log, job, enabled
        self._stop = threading.Event()
        self._thread = threading.Thread(target=self._watch, daemon=True)

    def __enter__(self) -> _ProgressWatch:
        if self.enabled:
            self._thread.start()
        return self

    def __exit__(self, *exc: object) -> None:
        self._stop.set()
        if self.enabled:
            self._thread.join(timeout=5)

    def _watch(self) -> None:
        total = self.job.total
        while not self._stop.wait(0.5):
            try:
                events = stored_events(self.driver, self.log)
            except Exception:  # progress is a nicety; the build reports real failures
                return
            stage = "writing events" if events < total else "linking events and aggregating"
            self.job.step(stage, events, total)
