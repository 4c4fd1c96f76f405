"""The kinds of log a path can hold, and the one decision which kind a path is.

As a reader of many formats decides once what it was given, :func:`kind_of` looks at a path
once, trying :data:`KINDS` in their order: the first whose test holds is the path's kind. A
new convention of storing logs is one :class:`LogKind` here and its reader.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

from robotale.eventlog import ocel
from robotale.eventlog.dataset import MANIFEST, WRITING


@dataclass(frozen=True)
class LogKind:
    """A kind of log: its name, what it is in a user's words, and the test of a path."""

    name: str
    what: str
    holds: Callable[[Path], bool]


def is_parquet(path: str | Path) -> bool:
    """Whether ``path`` is read as Parquet: a ``.parquet`` file or folder, or a folder robotale
    wrote a dataset into (under another name)."""
    path = Path(path)
    if path.suffix.lower() == ".parquet":
        return True
    return path.is_dir() and any((path / name).exists() for name in (MANIFEST, WRITING))


PARQUET = LogKind("parquet", "a Parquet event log (a file or a dataset folder)", is_parquet)
#: any other folder: a rosbag2 directory or a folder of them (the preparation says what is
#: missing when it is neither)
RECORDINGS = LogKind(
    "recordings", "rosbag2 recordings (a bag directory or a folder of runs)", Path.is_dir
)
OCEL = LogKind("ocel", "an OCEL 2.0 log", lambda path: ocel.encoding(path) is not None)
XES = LogKind("xes", "an XES event log", lambda path: path.suffix.lower() == ".xes")
#: the last resort: whatever else is read as CSV, and refused with a sentence if it is not
CSV = LogKind("csv", "a CSV event log", lambda path: True)

#: every kind, in the order they are tried
KINDS: tuple[LogKind, ...] = (PARQUET, RECORDINGS, OCEL, XES, CSV)


def kind_of(path: str | Path) -> LogKind:
    """The kind of log at ``path``: the first of :data:`KINDS` that holds it."""
    return next(kind for kind in KINDS if kind.holds(Path(path)))
