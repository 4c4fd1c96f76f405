"""The preparation as a command runs it: a progress bar, the preparation's warnings and what
``--auto`` chose said on stderr, and (with ``--skip-bad``) a run that cannot be read left out
and named. ``prepare``, ``ingest``, ``annotate`` and ``demo`` all prepare through here."""

from __future__ import annotations

import sys
import warnings
from collections.abc import Callable, Iterator, Sequence
from contextlib import contextmanager
from pathlib import Path
from typing import Any

import pandas as pd

from robotale.eventlog.enrich import PreparationWarning
from robotale.eventlog.options import PrepareOptions
from robotale.eventlog.prepare import prepare


def prepare_recordings(
    source: Path,
    options: PrepareOptions | None = None,
    *,
    executor: str | None = None,
    skipped: list[Path] | None = None,
) -> pd.DataFrame:
    """The event log of the recordings at ``source``; ``executor``: read in this process
    unless told. Given a list ``skipped``, a run that cannot be read is left out, added to it
    and named with why on stderr; without, it stops the preparation before anything is
    written."""
    keywords = (options or PrepareOptions()).keywords()
    skip = None if skipped is None else skipping(skipped)
    return prepare_reporting(source, executor=executor, skip_bad=skip, **keywords)


def prepare_reporting(source: Path, **options: Any) -> pd.DataFrame:
    """:func:`~robotale.eventlog.prepare.prepare` with a progress bar, its warnings (completes
    without a start ...) on stderr as one ``robotale: warning:`` line each."""
    with preparation_warnings():
        return prepare(source, progress=True, report=report_choice, **options)


def kept_runs(kept: int, skipped: Sequence[Path]) -> str:
    """How many runs a ``--skip-bad`` preparation kept, and which it left out."""
    left_out = f"; skipped {len(skipped)}: {', '.join(run.name for run in skipped)}"
    return f"kept {kept} of {kept + len(skipped)} run(s){left_out if skipped else ''}"


def skipping(skipped: list[Path]) -> Callable[[Path, str], None]:
    def skip(run: Path, why: str) -> None:
        skipped.append(run)
        print(f"robotale: skipped {run.name}: {why}", file=sys.stderr)

    return skip


@contextmanager
def preparation_warnings() -> Iterator[None]:
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


def report_choice(text: str) -> None:
    """What the preparation chose (``--auto``), on stderr so that stdout stays the summary."""
    print(f"robotale: {text}", file=sys.stderr)
