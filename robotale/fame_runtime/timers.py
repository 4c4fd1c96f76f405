"""Timer definitions (guideline G5): ISO 8601 date, duration and cycle.

``2023-10-01T12:00:00Z`` fires at that instant, ``PT1H30M`` after that long, ``R5/PT10S``
every 10 seconds five times (``R/PT10S``: for ever; ``R3/2023-10-01T12:00:00Z/PT1S``: from that
instant). Times are seconds since the Unix epoch, the engine clock's unit. Years and months in
a duration count as 365 and 30 days: a robot's timers are seconds to hours, and a calendar
would make a duration depend on the date it starts.
"""

from __future__ import annotations

import itertools
import re
from collections.abc import Iterator
from dataclasses import dataclass
from datetime import UTC, datetime

_NUMBER = r"(\d+(?:[.,]\d+)?)"
_DURATION = re.compile(
    rf"P(?:{_NUMBER}Y)?(?:{_NUMBER}M)?(?:{_NUMBER}W)?(?:{_NUMBER}D)?"
    rf"(?:T(?:{_NUMBER}H)?(?:{_NUMBER}M)?(?:{_NUMBER}S)?)?"
)
_UNIT_SECONDS = (365 * 86400, 30 * 86400, 7 * 86400, 86400, 3600, 60, 1)
_CYCLE = re.compile(r"R(\d*)/(.+)")

KINDS = ("timeDate", "timeDuration", "timeCycle")


def parse_duration(text: str) -> float:
    """Seconds in an ISO 8601 duration such as ``PT1M30S`` or ``P1DT2H``."""
    match = _DURATION.fullmatch(text.strip())
    if not match or not any(match.groups()) or text.strip().endswith("T"):
        raise ValueError(f"{text!r} is not an ISO 8601 duration such as PT10S or PT1H30M")
    return sum(
        float(value.replace(",", ".")) * unit
        for value, unit in zip(match.groups(), _UNIT_SECONDS, strict=True)
        if value
    )


def parse_date(text: str) -> float:
    """Epoch seconds of an ISO 8601 date-time; one without a zone is taken as UTC."""
    try:
        moment = datetime.fromisoformat(text.strip())
    except ValueError:
        raise ValueError(
            f"{text!r} is not an ISO 8601 date-time such as 2023-10-01T12:00:00Z"
        ) from None
    if moment.tzinfo is None:
        moment = moment.replace(tzinfo=UTC)
    return moment.timestamp()


@dataclass(frozen=True, slots=True)
class TimerSpec:
    """A parsed timer. ``repeat`` is None for an endless cycle."""

    kind: str  # timeDate | timeDuration | timeCycle
    text: str
    interval: float = 0.0
    at: float | None = None  # timeDate, or the start of a cycle
    until: float | None = None  # the end of a cycle
    repeat: int | None = 1
    deferred: bool = False  # the text has ${...} placeholders: parsed when armed

    def fire_times(self, now: float) -> Iterator[float]:
        """When the timer fires, armed at ``now`` (a date in the past fires at once)."""
        if self.kind == "timeDate":
            yield max(self.at or now, now)
            return
        if self.kind == "timeDuration":
            yield now + self.interval
            return
        first = self.at if self.at is not None else now + self.interval
        counts = range(self.repeat) if self.repeat is not None else itertools.count()
        for k in counts:
            when = first + k * self.interval
            if self.until is not None and when > self.until:
                return
            yield max(when, now)


def parse_timer(kind: str, text: str) -> TimerSpec:
    """A :class:`TimerSpec` from a timer definition's element name and text."""
    text = text.strip()
    if "${" in text and kind in KINDS:
        return TimerSpec(kind, text, deferred=True)
    if kind == "timeDate":
        return TimerSpec(kind, text, at=parse_date(text))
    if kind == "timeDuration":
        return TimerSpec(kind, text, interval=parse_duration(text))
    if kind != "timeCycle":
        raise ValueError(f"{kind!r} is not a timer kind ({', '.join(KINDS)})")
    return _parse_cycle(text)


def _parse_cycle(text: str) -> TimerSpec:
    match = _CYCLE.fullmatch(text)
    if not match:
        raise ValueError(f"{text!r} is not an ISO 8601 cycle such as R5/PT10S")
    repeat = int(match.group(1)) if match.group(1) else None
    parts = match.group(2).split("/")
    if len(parts) == 1:
        return TimerSpec("timeCycle", text, parse_duration(parts[0]), repeat=repeat)
    if len(parts) == 2 and parts[0].startswith("P"):
        interval, until = parse_duration(parts[0]), parse_date(parts[1])
        return TimerSpec("timeCycle", text, interval, until=until, repeat=repeat)
    if len(parts) == 2:
        start, interval = parse_date(parts[0]), parse_duration(parts[1])
        return TimerSpec("timeCycle", text, interval, at=start, repeat=repeat)
    raise ValueError(f"{text!r} is not an ISO 8601 cycle such as R5/PT10S")
