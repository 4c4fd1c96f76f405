"""ROS 2 QoS policies of a publisher or subscriber (thesis listing 5.7).

The compatibility rules (C-QoS, thesis 4.2) belong here too, next to the profile they judge.
"""

from __future__ import annotations

from dataclasses import dataclass


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
