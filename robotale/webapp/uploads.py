"""Uploaded files: checked, stored under generated names, unpacked safely, deleted after use.

An upload is kept as ``<token>.<kind>`` in the upload folder, never under the name the browser
sent, and only if its content is what its extension says (a CSV with a header line, an XES
document, an OCEL 2.0 log in JSON, XML or SQLite, a zip archive). A zipped bag folder is
unpacked member by member: absolute paths, ``..``, links and archives that unpack to more
than a limit (or than the free disk) are refused, and unpacking counts every byte it writes.
"""

from __future__ import annotations

import errno
import re
import secrets
import shutil
import stat
import time
import zipfile
from dataclasses import dataclass
from pathlib import Path, PurePosixPath
from typing import BinaryIO

from robotale.errors import InputError
from robotale.eventlog import ocel

#: an OCEL 2.0 encoding -> the kind (and stored ending) of its uploads
_OCEL_KINDS = {"json": "jsonocel", "xml": "xmlocel", "sqlite": "sqlite"}
#: extension -> kind of upload
KINDS = {
    ".csv": "csv",
    ".xes": "xes",
    ".zip": "zip",
    # OCEL 2.0, by the endings its reader knows; the stored copy's ending tells it the encoding
    **{suffix: _OCEL_KINDS[encoding] for suffix, encoding in ocel.SUFFIXES.items()},
}
#: what a text upload of each kind is, for messages
_TEXT_KINDS = {
    "csv": "CSV event log",
    "xes": "XES event log",
    "jsonocel": "OCEL 2.0 JSON log",
    "xmlocel": "OCEL 2.0 XML log",
}
#: how an SQLite database file begins
_SQLITE_HEADER = b"SQLite format 3\0"
_TOKEN = re.compile(r"[0-9a-f]{32}")
_SNIFF = 64 * 1024
#: uploads nobody ingested are removed after this many seconds
STALE_AFTER = 24 * 3600
#: an archive may unpack to this many times its own size (recordings and logs compress far
#: less; a few megabytes of zeros compress a thousandfold) ...
MAX_RATIO = 50
#: ... or to this many bytes, whichever is more
RATIO_FLOOR = 64 * 2**20
_CHUNK = 1024 * 1024


@dataclass(frozen=True)
class Upload:
    token: str
    path: Path
    kind: str
    filename: str  # as the user named it, for messages only

    @property
    def suggested_name(self) -> str:
        """A log name from the file's name: ``robotic_data.csv`` -> ``robotic_data``."""
        stem = PurePosixPath(self.filename.replace("\\", "/")).name
        for suffix in KINDS:
            stem = stem.removesuffix(suffix).removesuffix(suffix.upper())
        return re.sub(r"[^\w.\- ]+", "_", stem).strip() or "log"


def kind_of(filename: str) -> str:
    """The kind of upload a file name announces; an :class:`InputError` for any other."""
    suffix = PurePosixPath(filename.lower()).suffix
    if suffix not in KINDS:
        raise InputError(
            f"{filename!r} is not an event log robotale reads: upload a .csv or .xes log, an "
            "OCEL 2.0 log (.jsonocel, .xmlocel or .sqlite), or a .zip of a folder of rosbag2 "
            "recordings."
        )
    return KINDS[suffix]


def save(stream: BinaryIO, filename: str, folder: Path) -> Upload:
    """Store an uploaded file after checking that its content matches its extension."""
    kind = kind_of(filename)
    folder.mkdir(parents=True, exist_ok=True)
    token = secrets.token_hex(16)
    path = folder / f"{token}.{kind}"
    partial = path.with_suffix(".part")
    try:
        with partial.open("wb") as out:
            shutil.copyfileobj(stream, out, 1024 * 1024)
        _check_content(partial, kind, filename)
        partial.rename(path)
    finally:
        partial.unlink(missing_ok=True)
    return Upload(token, path, kind, filename)


def find(folder: Path, token: str, filename: str = "") -> Upload:
    """The stored upload ``token`` names (a token that is not one of ours finds nothing)."""
    if _TOKEN.fullmatch(token or ""):
        for kind in KINDS.values():
            path = folder / f"{token}.{kind}"
            if path.is_file():
                return Upload(token, path, kind, filename or path.name)
    raise InputError("That upload is gone (it was ingested or is too old): upload the file again.")


def discard(upload: Upload) -> None:
    upload.path.unlink(missing_ok=True)


def remove_stale(folder: Path, older_than: float = STALE_AFTER) -> int:
    """Delete uploads and unpacked folders left behind longer than ``older_than`` seconds."""
    if not folder.is_dir():
        return 0
    removed = 0
    deadline = time.time() - older_than
    for entry in folder.iterdir():
        if _TOKEN.fullmatch(entry.name.split(".")[0]) and entry.stat().st_mtime < deadline:
            if entry.is_dir():
                shutil.rmtree(entry, ignore_errors=True)
            else:
                entry.unlink(missing_ok=True)
            removed += 1
    return removed


def _check_content(path: Path, kind: str, filename: str) -> None:
    with path.open("rb") as stream:
        head = stream.read(_SNIFF)
    if kind == "zip":
        if not zipfile.is_zipfile(path):
            raise InputError(f"{filename!r} is not a zip archive.")
        return
    if kind == "sqlite":
        if not head.startswith(_SQLITE_HEADER):
            raise InputError(f"{filename!r} is not an SQLite database, so it is no OCEL 2.0 log.")
        return
    if not head.strip():
        raise InputError(f"{filename!r} is empty.")
    if b"\0" in head:
        raise InputError(f"{filename!r} is not a text file, so it is no {_TEXT_KINDS[kind]}.")
    text = head.decode("utf-8", errors="replace").lstrip("\ufeff \t\r\n")
    if not text:
        raise InputError(
            f"{filename!r} holds nothing but a byte order mark: it has no header line."
        )
    if kind == "xes" and not (text.startswith("<?xml") or text.startswith("<log")):
        raise InputError(f"{filename!r} is not an XES document: it does not start with XML.")
    if kind == "jsonocel" and not text.startswith("{"):
        raise InputError(f"{filename!r} is not an OCEL 2.0 JSON log: it does not start with {{.")
    if kind == "xmlocel" and not text.startswith("<"):
        raise InputError(f"{filename!r} is not an OCEL 2.0 XML log: it does not start with XML.")
    if kind == "csv" and ("," not in text.splitlines()[0] and ";" not in text.splitlines()[0]):
        raise InputError(
            f"{filename!r} does not start with a header line of comma-separated column names."
        )


def unpack(
    upload: Upload, limit_bytes: int, ratio: int = MAX_RATIO, floor: int = RATIO_FLOOR
) -> Path:
    """Unpack a zip upload into a folder next to it; refuses unsafe or oversized archives.

    An archive may unpack to ``limit_bytes``, and to no more than ``ratio`` times its own size
    (at least ``floor``): a few megabytes of zeros make gigabytes. The sizes the archive
    declares are checked first, against those limits and the free disk; then every byte
    written is counted, and unpacking stops before the first byte past the limit."""
    allowed = min(limit_bytes, max(floor, upload.path.stat().st_size * ratio))
    target = upload.path.with_suffix("")
    target.mkdir(exist_ok=False)
    try:
        with zipfile.ZipFile(upload.path) as archive:
            members = archive.infolist()
            _check_members(members, upload.filename, allowed)
            budget = _Budget(upload.filename, allowed, target)
            budget.check_disk(sum(member.file_size for member in members))
            for member in members:
                _extract(archive, member, target, budget)
    except (zipfile.BadZipFile, EOFError) as error:
        shutil.rmtree(target, ignore_errors=True)
        raise InputError(f"{upload.filename!r} is a damaged zip archive ({error}).") from None
    except OSError as error:
        shutil.rmtree(target, ignore_errors=True)
        if error.errno == errno.ENOSPC:
            raise InputError(
                f"The disk of {target.parent} is full: unpacking {upload.filename!r} needs "
                f"{_megabytes(budget.written + budget.free_needed)} MB there."
            ) from None
        raise
    except BaseException:
        shutil.rmtree(target, ignore_errors=True)
        raise
    return target


@dataclass
class _Budget:
    """The bytes an archive may still write, counted as they are written."""

    filename: str
    limit: int
    target: Path
    written: int = 0
    free_needed: int = 0

    def check_disk(self, declared: int) -> None:
        free = shutil.disk_usage(self.target).free
        self.free_needed = declared
        if declared > free:
            raise InputError(
                f"Unpacking {self.filename!r} needs {_megabytes(declared)} MB, but the disk of "
                f"{self.target.parent} has {_megabytes(free)} MB free."
            )

    def take(self, size: int) -> None:
        if self.written + size > self.limit:
            raise InputError(
                f"{self.filename!r} unpacks to more than the limit of "
                f"{_megabytes(self.limit)} MB; nothing past it was written."
            )
        self.written += size


def _megabytes(size: int) -> str:
    return f"{size / 2**20:.1f}".removesuffix(".0")


def _check_members(members: list[zipfile.ZipInfo], filename: str, limit_bytes: int) -> None:
    total = 0
    for member in members:
        name = PurePosixPath(member.filename)
        if name.is_absolute() or ".." in name.parts or "\\" in member.filename:
            raise InputError(f"{filename!r} holds an unsafe path {member.filename!r}.")
        if stat.S_ISLNK(member.external_attr >> 16):
            raise InputError(f"{filename!r} holds a link ({member.filename!r}); zip plain files.")
        total += member.file_size
    if total > limit_bytes:
        raise InputError(
            f"{filename!r} unpacks to {_megabytes(total)} MB, more than the limit of "
            f"{_megabytes(limit_bytes)} MB."
        )


def _extract(
    archive: zipfile.ZipFile, member: zipfile.ZipInfo, target: Path, budget: _Budget
) -> None:
    destination = target.joinpath(*PurePosixPath(member.filename).parts)
    if member.is_dir():
        destination.mkdir(parents=True, exist_ok=True)
        return
    destination.parent.mkdir(parents=True, exist_ok=True)
    with archive.open(member) as source, destination.open("wb") as out:
        while chunk := source.read(_CHUNK):
            budget.take(len(chunk))
            out.write(chunk)
