"""Writing result files whole: every file appears complete, or none of them does."""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path

from robotale.errors import InputError
from robotale.files import write_files


def write_texts(outputs: Sequence[tuple[Path, str]]) -> None:
    """Write each text to its path; a failure leaves no file written or half-written."""
    for path, _ in outputs:
        if not path.parent.is_dir():
            raise InputError(f"cannot write {path}: the folder {path.parent} does not exist.")
    try:
        write_files(outputs)
    except OSError as error:
        raise InputError(
            f"cannot write {error.filename or 'the output'}: {error.strerror}."
        ) from error
