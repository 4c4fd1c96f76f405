"""Writing files whole: a file appears complete at its path, or it does not change.

Every write goes to a temporary file in the target's folder (so the rename stays on one file
system and is atomic), is flushed to the disk, and is then renamed over the target. The file
gets the permissions of a normally created one, 0666 less the umask (``mkstemp`` would leave
0600, which other users and tools reading the result would not expect).
"""

from __future__ import annotations

import contextlib
import errno
import os
import tempfile
from collections.abc import Iterator, Sequence
from pathlib import Path
from typing import IO, Any

from robotale.errors import InputError


@contextlib.contextmanager
def atomic_file(path: str | Path, mode: str = "w") -> Iterator[IO[Any]]:
    """A file opened for writing (``"w"`` text in UTF-8, ``"wb"`` bytes) that appears at
    ``path`` only once the block ends without an exception. The folder must exist."""
    with _staged(Path(path), mode) as (file, temporary):
        yield file
    _replace([(temporary, Path(path))])


def write_file(path: str | Path, data: str | bytes) -> None:
    """Write ``data`` (text as UTF-8) to ``path`` whole."""
    write_files([(Path(path), data)])


def write_files(outputs: Sequence[tuple[Path, str | bytes]]) -> None:
    """Write each text to its path: all are written whole before any of them is renamed into
    place, so a failure (a full disk, a folder that cannot be written) changes none of them."""
    staged: list[tuple[str, Path]] = []
    try:
        for path, data in outputs:
            with _staged(Path(path), "wb" if isinstance(data, bytes) else "w") as (file, name):
                file.write(data)
            staged.append((name, Path(path)))
    except BaseException:
        for name, _ in staged:
            _remove(name)
        raise
    _replace(staged)


@contextlib.contextmanager
def _staged(path: Path, mode: str) -> Iterator[tuple[IO[Any], str]]:
    """A temporary file next to ``path`` and its name; when the block ends it is synced to
    the disk and has a normal file's permissions (it is removed if the block raises)."""
    try:
        handle, name = tempfile.mkstemp(dir=path.parent, prefix=f".{path.name}.", suffix=".tmp")
    except OSError as error:
        raise InputError(f"Cannot write {path}: {error.strerror or error}.") from None
    try:
        encoding = None if "b" in mode else "utf-8"
        with os.fdopen(handle, mode, encoding=encoding) as file:
            yield file, name
            # Without fsync a crash soon after the rename can leave an empty file behind.
            file.flush()
            os.fsync(file.fileno())
        os.chmod(name, 0o666 & ~umask())
    except OSError as error:
        written = _size(name)
        _remove(name)
        if error.errno in (errno.ENOSPC, errno.EDQUOT):
            raise InputError(_disk_full(path, written)) from None
        raise
    except BaseException:
        _remove(name)
        raise


def _size(name: str) -> int:
    try:
        return os.stat(name).st_size
    except OSError:
        return 0


def _disk_full(path: Path, written: int) -> str:
    fitted = f"{written / 2**20:.1f} MB" if written >= 2**20 else f"{written / 1024:.0f} KB"
    return (
        f"The disk of {path.parent} is full: {path} needs more than the {fitted} that "
        "fitted there; nothing was written (free some space or write elsewhere)."
    )


def _replace(staged: Sequence[tuple[str, Path]]) -> None:
    try:
        for name, path in staged:
            os.replace(name, path)
    finally:  # whatever could not be renamed (a target that is a folder ...) is not left over
        for name, _ in staged:
            _remove(name)


def _remove(name: str) -> None:
    with contextlib.suppress(OSError):
        os.unlink(name)


def umask() -> int:
    """The process's umask (reading it means setting it, so it is set straight back)."""
    current = os.umask(0)
    os.umask(current)
    return current
