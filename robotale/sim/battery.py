"""A robot's battery: drains with time, motion and flight, refills on a charging base, warns
when low.

The warning is what real battery monitors do: a message on ``/<robot>/low_battery``
(``std_msgs/msg/Empty``) when the charge falls below the threshold, repeated every
``warn_period`` seconds while it stays low and the robot is not charging, so a process that
starts later still hears it.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

from robotale.sim.messages import header

#: sensor_msgs/msg/BatteryState power_supply_status values
CHARGING, DISCHARGING, FULL = 1, 2, 4


@dataclass
class Battery:
    level: float  # 0-1
    drain: float  # per second, always
    move_drain: float  # per second at 1 m/s
    charge_rate: float  # per second on a charging base
    low: float  # the low_battery threshold
    warn_period: float
    flight_drain: float = 0.0  # per second more while airborne (a drone's rotors hovering)
    fault_drain: float = 0.0  # per second, from a "battery empties" fault on
    charging: bool = False
    _warned_at: float | None = None

    @property
    def empty(self) -> bool:
        return self.level <= 0.0

    def step(
        self, dt: float, speed: float, on_charger: bool, now: float, flying: bool = False
    ) -> bool:
        """Advance ``dt`` seconds (``flying``: airborne); True when a low_battery warning is
        due now."""
        self.charging = on_charger and self.level < 1.0 and not self.fault_drain
        if self.charging:
            self.level = min(1.0, self.level + self.charge_rate * dt)
        else:
            use = self.drain + self.move_drain * abs(speed) + self.fault_drain
            if flying:
                use += self.flight_drain
            self.level = max(0.0, self.level - use * dt)
        if self.level >= self.low:
            self._warned_at = None
            return False
        due = self._warned_at is None or now - self._warned_at >= self.warn_period - 1e-9
        if due and not self.charging:
            self._warned_at = now
            return True
        return False

    def message(self, now: float, robot: str) -> dict[str, Any]:
        """A ``sensor_msgs/msg/BatteryState`` (percentage 0-1)."""
        if self.charging:
            status = CHARGING
        elif self.level >= 1.0:
            status = FULL
        else:
            status = DISCHARGING
        return {
            "header": header(now, f"{robot}/battery"),
            "percentage": round(self.level, 6),
            "power_supply_status": status,
            "present": True,
        }
