"""Where ``--out`` writes: a local path, or an fsspec URL that every worker reaches.

A plain path or a ``file://`` URL is this machine's (or a share mounted at the same path on
every machine). Any other URL (``ftp://``, ``sftp://``, ``s3://``, ``gs://``, ``abfs://`` ...)
names a filesystem of fsspec, whose package must be installed wherever robotale runs
(``s3fs``, ``gcsfs`` ...). A file appears whole on either: written to a hidden name in its
folder, then moved to its own (a rename wherever the filesystem has one).
"""

from __future__ import annotations

import ftplib
import posixpath
import uuid
from collections.abc import Iterator
from contextlib import contextmanager
from dataclasses import dataclass
from pathlib import Path

import fsspec
from fsspec import AbstractFileSystem
from fsspec.implementations.local import LocalFileSystem

from robotale.errors import InputError
from robotale.files import write_file


@dataclass(frozen=True)
class Place:
    """A folder or file on a filesystem: ``fs`` and the ``path`` in it; ``text`` is how the
    user named it (for sentences)."""

    fs: AbstractFileSystem
    path: str
    text: str

    @property
    def local(self) -> bool:
        return isinstance(self.fs, LocalFileSystem)

    @property
    def name(self) -> str:
        return posixpath.basename(self.path.rstrip("/"))

    def child(self, *parts: str) -> Place:
        path = posixpath.join(self.path, *parts)
        return Place(self.fs, path, posixpath.join(self.text.rstrip("/"), *parts))

    def exists(self) -> bool:
        self.fs.invalidate_cache()  # other processes (the workers) write here too
        return bool(self.fs.exists(self.path))

    def is_dir(self) -> bool:
        self.fs.invalidate_cache()
        return bool(self.fs.isdir(self.path))

    def names(self) -> list[str]:
        """The names of what this folder holds."""
        self.fs.invalidate_cache()
        listed = self.fs.ls(self.path, detail=False)
        return sorted(posixpath.basename(str(p).rstrip("/")) for p in listed)

    def read_bytes(self) -> bytes:
        return bytes(self.fs.cat_file(self.path))

    def write_whole(self, data: str | bytes) -> None:
        """``data`` (text as UTF-8) at this place, whole or not at all."""
        with writing(self):
            self._write_whole(data)

    def _write_whole(self, data: str | bytes) -> None:
        folder = posixpath.dirname(self.path)
        self.fs.makedirs(folder, exist_ok=True)
        if self.local:
            write_file(self.path, data)
            return
        raw = data.encode("utf-8") if isinstance(data, str) else data
        hidden = posixpath.join(folder, f".{self.name}.{uuid.uuid4().hex}.tmp")
        self.fs.pipe_file(hidden, raw)
        self.fs.mv(hidden, self.path)

    def remove(self) -> None:
        if not self.exists():
            return
        if self.fs.isfile(self.path):  # a recursive rm lists a file as a folder on FTP
            self.fs.rm_file(self.path)
        else:
            self.fs.rm(self.path, recursive=True)


def is_url(text: str | Path) -> bool:
    return isinstance(text, str) and ("://" in text or "::" in text)


def place(target: str | Path) -> Place:
    """The place ``target`` names; a plain path is made absolute (a Dask worker's working
    folder is not ours)."""
    text = str(target)
    if not is_url(target):
        return Place(LocalFileSystem(), str(Path(text).resolve()), text)
    try:
        fs, path = fsspec.core.url_to_fs(text)
    except ImportError as error:
        raise InputError(
            f"{text}: writing there needs a package that is not installed ({error.name or error})."
        ) from None
    except ValueError as error:
        raise InputError(f"{text} is not a destination robotale can write to: {error}.") from None
    except OSError as error:
        raise InputError(f"{text} cannot be reached: {error.strerror or error}.") from None
    return Place(fs, path, text)


def local_path(target: str | Path) -> Path | None:
    """``target`` as a local path when it is one (a plain path or a ``file://`` URL)."""
    if not is_url(target):
        return Path(target)
    found = place(target)
    return Path(found.path) if found.local else None


#: what a filesystem of fsspec raises when its destination refuses or drops a write (ftp://
#: passes on ftplib's own errors)
REFUSALS = (OSError, EOFError, ftplib.Error)


@contextmanager
def writing(target: Place) -> Iterator[None]:
    """Writes to ``target`` whose refusal (permissions, a lost connection, a full disk) is one
    sentence naming it rather than the filesystem's traceback."""
    try:
        yield
    except InputError:
        raise
    except REFUSALS as error:
        why = str(error).strip() or type(error).__name__
        raise InputError(f"{target.text} could not be written: {why}.") from None


def upload_folder(folder: Path, target: Place) -> None:
    """Copy the files of the local ``folder`` to ``target`` through a hidden folder next to
    it, which is then moved to ``target``'s name: ``target`` appears complete or not at all
    (on a filesystem without a rename, fsspec's move copies; see docs/scale.md)."""
    with writing(target):
        _upload_folder(folder, target)


def _upload_folder(folder: Path, target: Place) -> None:
    parent = posixpath.dirname(target.path)
    hidden = posixpath.join(parent, f".{target.name}.partial")
    fs = target.fs
    if fs.exists(hidden):
        fs.rm(hidden, recursive=True)
    fs.makedirs(hidden, exist_ok=True)
    for file in sorted(p for p in folder.rglob("*") if p.is_file()):
        remote = posixpath.join(hidden, *file.relative_to(folder).parts)
        fs.makedirs(posixpath.dirname(remote), exist_ok=True)
        fs.put_file(str(file), remote)
    try:
        fs.mv(hidden, target.path, recursive=True)
    except BaseException:
        fs.rm(hidden, recursive=True)
        raise
