"""Writing result files whole: every file appears complete, or none of them does."""

from __future__ import annotations

import os
import tempfile
from collections.abc import Sequence
from pathlib import Path

from robotale.errors import InputError


def write_texts(outputs: Sequence[tuple[Path, str]]) -> None:
    """Write each text to its path; a failure leaves no file written or half-written."""
    for path, _ in outputs:
        if not path.parent.is_dir():
            raise InputError(f"cannot write {path}: the folder {path.parent} does not exist.")
    staged: list[tuple[Path, Path]] = []
    try:
        for path, text in outputs:
            staged.append((_stage(path, text), path))
    except OSError as error:
        for temporary, _ in staged:
            temporary.unlink(missing_ok=True)
        raise InputError(
            f"cannot write {error.filename or 'the output'}: {error.strerror}."
        ) from error
    for temporary, path in staged:
        os.replace(temporary, path)


def _stage(path: Path, text: str) -> Path:
    handle, name = tempfile.mkstemp(dir=path.parent, prefix=f".{path.name}.", suffix=".tmp")
    try:
        with os.fdopen(handle, "w", encoding="utf-8") as stream:
            stream.write(text)
    except OSError:
        Path(name).unlink(missing_ok=True)
        raise
    return Path(name)
