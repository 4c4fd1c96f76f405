"""ROS 2 QoS policies of a publisher or subscriber (thesis listing 5.7) and the rules that decide
whether a publisher and a subscriber can talk (C-QoS, thesis 4.2 and table 4.1).

ROS 2 matches a publisher and a subscriber only when what the publisher *offers* is at least
what the subscriber *requests*, policy by policy:

- reliability: a best-effort publisher cannot serve a reliable subscriber;
- durability: a volatile publisher cannot serve a transient-local subscriber;
- deadline: the publisher's period must not be longer than the subscriber's;
- liveliness: an automatic publisher cannot serve a manual-by-topic subscriber;
- lease duration: the publisher's lease must not be longer than the subscriber's.

History, depth and lifespan never prevent a match.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, replace
from typing import Any

from robotale.fame_runtime.timers import parse_duration


@dataclass(frozen=True, slots=True)
class QoS:
    """A QoS profile. Durations are seconds; ``None`` means the ROS default (infinite)."""

    reliability: str = "reliable"  # reliable | best_effort
    durability: str = "volatile"  # volatile | transient_local
    history: str = "keep_last"  # keep_last | keep_all
    depth: int = 10
    deadline: float | None = None
    lifespan: float | None = None
    liveliness: str = "automatic"  # automatic | manual_by_topic
    lease_duration: float | None = None


DEFAULT_QOS = QoS()

_CHOICES = {
    "reliability": ("reliable", "best_effort"),
    "durability": ("volatile", "transient_local"),
    "history": ("keep_last", "keep_all"),
    "liveliness": ("automatic", "manual_by_topic"),
}
_DURATIONS = ("deadline", "lifespan", "lease_duration")
POLICIES = (*_CHOICES, "depth", *_DURATIONS)


def policy_name(name: str) -> str | None:
    """The QoS field a policy name in a model means (``qos.lease-duration`` -> lease_duration),
    or None when it is not a QoS policy."""
    key = _normal(name.split(":")[-1].split(".")[-1])
    return key if key in POLICIES else None


def qos_from_policies(policies: Mapping[str, str]) -> QoS:
    """A profile from ``name -> value`` text as written in a model, the ROS defaults for the
    policies it leaves out; ValueError names a bad one.

    Values are case and spacing tolerant (``Best Effort``); durations are seconds or ISO 8601
    (``PT2S``); ``infinite`` or an empty value keeps the ROS default.
    """
    fields: dict[str, Any] = {}  # each policy's value, of its field's type
    for name, text in policies.items():
        key = policy_name(name)
        if key is None:
            raise ValueError(f"{name!r} is not a QoS policy ({', '.join(POLICIES)})")
        fields[key] = _policy_value(key, text)
    return replace(DEFAULT_QOS, **fields)


def _policy_value(key: str, text: str) -> object:
    value = _normal(text)
    if key in _CHOICES:
        if value == "system_default":
            return getattr(DEFAULT_QOS, key)
        if value not in _CHOICES[key]:
            raise ValueError(f"QoS {key} {text!r} is not one of {', '.join(_CHOICES[key])}")
        return value
    if key == "depth":
        if not value.isdigit():
            raise ValueError(f"QoS depth {text!r} is not a whole number")
        return int(value)
    if value in ("", "infinite", "default", "system_default"):
        return None
    try:
        return float(value)
    except ValueError:
        try:
            return parse_duration(text.strip().upper())
        except ValueError:
            raise ValueError(f"QoS {key} {text!r} is not a number of seconds") from None


def _normal(text: str) -> str:
    return "_".join(text.strip().lower().replace("-", " ").replace("_", " ").split())


#: (policy, an offered value, a requested value it cannot serve)
_ORDERED = (
    ("reliability", "best_effort", "reliable"),
    ("durability", "volatile", "transient_local"),
    ("liveliness", "automatic", "manual_by_topic"),
)
_PERIODS = ("deadline", "lease_duration")


def incompatibilities(offered: QoS, requested: QoS) -> list[str]:
    """Why a publisher offering ``offered`` cannot serve a subscriber requesting ``requested``
    (empty when they are compatible)."""
    reasons = []
    for policy, weak, strong in _ORDERED:
        if getattr(offered, policy) == weak and getattr(requested, policy) == strong:
            reasons.append(
                f"{policy}: the publisher offers {weak}, the subscriber requests {strong}"
            )
    for policy in _PERIODS:
        mine, wanted = getattr(offered, policy), getattr(requested, policy)
        if _longer(mine, wanted):
            reasons.append(
                f"{policy}: the publisher offers {_seconds(mine)}, longer than the "
                f"{_seconds(wanted)} the subscriber requests"
            )
    return reasons


def pair_problems(
    offered: QoS, requested: QoS, published_type: str | None, expected_type: str | None
) -> list[str]:
    """Why a publisher (its QoS and message type) and a subscriber cannot talk: the QoS rules
    above, and a message type that differs on the two sides (DDS matches only same-typed
    endpoints). An unknown type (None or empty) matches any."""
    reasons = incompatibilities(offered, requested)
    if published_type and expected_type and published_type != expected_type:
        reasons.append(
            f"type: the publisher sends {published_type}, the subscriber expects {expected_type}"
        )
    return reasons


def _longer(offered: float | None, requested: float | None) -> bool:
    """Whether an offered period is longer than the requested one (None is infinite)."""
    if requested is None:
        return False
    return offered is None or offered > requested


def _seconds(value: float | None) -> str:
    return "infinite" if value is None else f"{value:g} s"
