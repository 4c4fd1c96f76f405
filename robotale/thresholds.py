"""Thresholds more than one part counts with, each written once.

Kept free of imports so that the command line's help (which names them) stays fast.
"""

from __future__ import annotations

#: the battery level, in percent, below which a robot's battery counts as low: where the
#: simulated robots warn ``low_battery`` unless a world says otherwise, and where the battery
#: perspective and the findings see a low-battery moment unless told another
LOW_BATTERY_PERCENT = 20.0

#: seconds a message may take from its send to its receive before ``robotale monitor`` alerts,
#: unless told another per message type: a message on a robot network arrives within
#: milliseconds, or its sender retries within seconds
MESSAGE_TIMEOUT = 5.0

#: the share of an activity's earlier durations past which an instance counts as slow: the
#: Mission page's "slow activity" moments and ``robotale monitor``'s overdue-activity alert
SLOW_QUANTILE = 0.95
