"""Thresholds more than one part counts with, each written once.

Kept free of imports so that the command line's help (which names them) stays fast.
"""

from __future__ import annotations

#: the battery level, in percent, below which a robot's battery counts as low: where the
#: simulated robots warn ``low_battery`` unless a world says otherwise, and where the battery
#: perspective and the findings see a low-battery moment unless told another
LOW_BATTERY_PERCENT = 20.0
