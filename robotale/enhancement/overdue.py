"""What a live run should have done by now: a message its receiver should have caught, an
activity that should have ended. Each is begun with a limit, ended when the run shows it done,
and reported once when the limit passed first.

The limits: a message's is given per message type (the label of the send that tags it) or a
default; an activity's is the 95th percentile of its durations in earlier runs.
"""

from __future__ import annotations

from collections.abc import Hashable, Iterable, Sequence
from dataclasses import dataclass, field

import numpy as np
import pandas as pd

from robotale.discovery.instances import activity_instances
from robotale.errors import InputError
from robotale.eventlog.schema import ACTIVITY
from robotale.thresholds import MESSAGE_TIMEOUT, SLOW_QUANTILE


@dataclass(frozen=True)
class Pending:
    """Something begun at ``stamp`` that should end within ``limit`` seconds."""

    key: Hashable
    stamp: float
    limit: float


@dataclass
class Overdue:
    """Things begun and not yet ended; each reported once, when its limit passed."""

    pending: dict[Hashable, Pending] = field(default_factory=dict)

    def begin(self, key: Hashable, stamp: float, limit: float) -> None:
        self.pending[key] = Pending(key, stamp, limit)

    def end(self, key: Hashable) -> None:
        self.pending.pop(key, None)

    def due(self, now: float) -> list[Pending]:
        """Those whose limit passed by ``now``, oldest first; forgotten once returned."""
        late = sorted(
            (p for p in self.pending.values() if now - p.stamp > p.limit), key=lambda p: p.stamp
        )
        for p in late:
            del self.pending[p.key]
        return late


@dataclass(frozen=True)
class MessageLimits:
    """Seconds from a send to its receive, per message type, else ``default``."""

    default: float = MESSAGE_TIMEOUT
    per_type: dict[str, float] = field(default_factory=dict)

    def of(self, kind: str) -> float:
        return self.per_type.get(kind, self.default)

    @classmethod
    def parse(cls, specs: Sequence[str]) -> MessageLimits:
        """From ``SECONDS`` (the default) and ``TYPE=SECONDS`` texts (``--message-timeout``)."""
        default, per_type = MESSAGE_TIMEOUT, {}
        for spec in specs:
            kind, sep, seconds = spec.rpartition("=")
            value = _seconds(seconds, spec)
            if sep:
                per_type[kind.strip()] = value
            else:
                default = value
        return cls(default, per_type)


def _seconds(text: str, spec: str) -> float:
    try:
        value = float(text)
    except ValueError:
        value = float("nan")
    if not value > 0 or value == float("inf"):
        raise InputError(
            f"--message-timeout {spec!r} is not SECONDS or TYPE=SECONDS with seconds above 0."
        )
    return value


def duration_limits(logs: Iterable[pd.DataFrame]) -> dict[str, float]:
    """``{activity: seconds}``: the :data:`~robotale.thresholds.SLOW_QUANTILE` quantile of the
    durations of each activity's finished instances in ``logs`` (earlier runs); activities
    that only happen in an instant (durations all 0) have none."""
    durations = [_finished(log) for log in logs]
    found = pd.concat(durations, ignore_index=True) if durations else pd.DataFrame()
    if found.empty:
        return {}
    limits = found.groupby(ACTIVITY)["duration"].quantile(SLOW_QUANTILE)
    return {str(a): float(s) for a, s in limits.items() if s > 0}


def _finished(log: pd.DataFrame) -> pd.DataFrame:
    instances = activity_instances(log)
    done = instances[instances["finished"].astype(bool)]
    return pd.DataFrame(
        {ACTIVITY: done[ACTIVITY].astype(str), "duration": done["duration"].astype(np.float64)}
    )
