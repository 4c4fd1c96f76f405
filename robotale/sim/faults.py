"""Faults a user models, written ``KIND:TARGET[@TIME][,key=value ...]``:

- ``die:tractor_1@60``: the robot dies 60 s into the run: it stops where it is, its sensors
  fall silent and its engine ends without a tag more (its computer is gone).
- ``drop:/closest_tractor,to=tractor_2,nth=1``: deliveries on a topic are lost; ``to`` limits
  it to one receiver, ``nth`` to the n-th message on the topic, ``@T1-T2`` to messages sent in
  that time window. The sender's tag and the recording still have the message; the receiver
  never tags it, as on a real lossy network.
- ``battery:drone@40,rate=0.02``: from 40 s the battery empties at 2 % a second (default
  1 %): the robot warns low_battery, and at zero it stops (a drone drops). ``for=10`` ends the
  drain after 10 s (a stalled motor, a short circuit); meanwhile the battery cannot charge.

``@T1-T2`` draws the time uniformly per run; ``p=0.3`` applies the fault in that share of
the runs. Both draws come from the run's seed, so a run replays with the same faults.
"""

from __future__ import annotations

from collections import defaultdict
from collections.abc import Callable, Iterable, Mapping
from dataclasses import dataclass
from typing import Any

import numpy as np

from robotale.errors import InputError
from robotale.fame_runtime.bus import Envelope, Subscription

KINDS = ("die", "drop", "battery")
_KEYS = {"die": {"p"}, "drop": {"p", "to", "nth"}, "battery": {"p", "rate", "for"}}


@dataclass(frozen=True)
class Fault:
    text: str
    kind: str
    target: str  # a robot, or the topic of a drop
    window: tuple[float, float] | None = None  # seconds after the start
    receiver: str = ""
    nth: int = 0
    rate: float = 0.01
    probability: float = 1.0
    duration: float | None = None  # battery: how long the drain lasts (None: for good)


@dataclass(frozen=True)
class Planned:
    """A fault as one run has it: applied or not, and when."""

    fault: Fault
    applied: bool
    at: float | None  # seconds after the start (die, battery)

    def as_dict(self) -> dict[str, Any]:
        return {"fault": self.fault.text, "applied": self.applied, "at": self.at}


def parse_fault(text: str, robots: Iterable[str]) -> Fault:
    """One fault; an InputError names what is wrong with it."""
    robots = list(robots)
    head, *options = [part.strip() for part in text.split(",")]
    kind, sep, rest = head.partition(":")
    if kind not in KINDS or not sep:
        raise InputError(
            f"fault {text!r} must start with one of {', '.join(k + ':' for k in KINDS)}"
        )
    target, _, when = rest.partition("@")
    values = _options(text, kind, options)
    fault = Fault(
        text=text,
        kind=kind,
        target=target.strip(),
        window=_window(text, when) if when else None,
        receiver=values.get("to", ""),
        nth=int(_number(text, "nth", values.get("nth", "0"))),
        rate=_number(text, "rate", values.get("rate", "0.01")),
        probability=_number(text, "p", values.get("p", "1")),
        duration=_number(text, "for", values["for"]) if "for" in values else None,
    )
    _check(fault, robots)
    return fault


def _options(text: str, kind: str, options: list[str]) -> dict[str, str]:
    values = {}
    for option in options:
        key, sep, value = option.partition("=")
        if not sep or key.strip() not in _KEYS[kind]:
            raise InputError(
                f"fault {text!r}: {option!r} is not one of "
                f"{', '.join(k + '=...' for k in sorted(_KEYS[kind]))}"
            )
        values[key.strip()] = value.strip()
    return values


def _number(text: str, name: str, value: str) -> float:
    try:
        number = float(value)
    except ValueError:
        raise InputError(f"fault {text!r}: {name}={value!r} is not a number") from None
    if number < 0:
        raise InputError(f"fault {text!r}: {name} must not be negative")
    return number


def _window(text: str, when: str) -> tuple[float, float]:
    low, _, high = when.partition("-")
    start = _number(text, "the time", low)
    end = _number(text, "the time", high) if high else start
    if end < start:
        raise InputError(f"fault {text!r}: the time window {when} ends before it starts")
    return (start, end)


def _check(fault: Fault, robots: list[str]) -> None:
    if fault.kind == "drop":
        if not fault.target.startswith("/"):
            raise InputError(f"fault {fault.text!r}: a drop names a topic such as /weed_position")
        if fault.receiver and fault.receiver not in robots:
            raise InputError(
                f"fault {fault.text!r}: there is no robot {fault.receiver!r} "
                f"(robots: {', '.join(robots)})"
            )
    else:
        if fault.target not in robots:
            raise InputError(
                f"fault {fault.text!r}: there is no robot {fault.target!r} "
                f"(robots: {', '.join(robots)})"
            )
        if fault.window is None:
            raise InputError(f"fault {fault.text!r}: say when with @SECONDS (or @FROM-TO)")
    if fault.probability > 1:
        raise InputError(f"fault {fault.text!r}: p must lie between 0 and 1")


def plan(faults: Iterable[Fault], seed: int) -> list[Planned]:
    """Which faults a run has and when, drawn from the run's seed."""
    rng = np.random.default_rng([seed, 0xFA])
    planned = []
    for fault in faults:
        applied = bool(rng.uniform() < fault.probability) if fault.probability < 1 else True
        at = None
        if fault.kind != "drop" and fault.window is not None:
            low, high = fault.window
            at = round(float(rng.uniform(low, high)), 3) if high > low else low
        planned.append(Planned(fault, applied, at))
    return planned


def drop_rule(
    planned: Iterable[Planned], start: float
) -> Callable[[Envelope, Subscription], bool] | None:
    """The bus rule losing the deliveries the applied drop faults describe (None: no drops)."""
    drops = [p.fault for p in planned if p.applied and p.fault.kind == "drop"]
    if not drops:
        return None
    order: Mapping[str, dict[Any, int]] = defaultdict(dict)

    def lost(envelope: Envelope, subscription: Subscription) -> bool:
        seen = order[envelope.topic]
        key = envelope.msg_id or (envelope.stamp, envelope.sender)
        number = seen.setdefault(key, len(seen) + 1)
        return any(_matches(f, envelope, subscription, number, start) for f in drops)

    return lost


def _matches(fault: Fault, envelope: Envelope, subscription, number: int, start: float) -> bool:
    if envelope.topic != fault.target:
        return False
    if fault.receiver and subscription.owner != fault.receiver:
        return False
    if fault.nth and number != fault.nth:
        return False
    if fault.window is not None:
        low, high = fault.window
        return low - 1e-9 <= envelope.stamp - start <= high + 1e-9
    return True
