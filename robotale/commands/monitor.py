"""``robotale monitor``: watch live robots over DDS, storing each tag in Neo4j as it arrives
and, every second, the events heard since as an append to the live run's event knowledge
graph (the log grows while the run goes on, and is complete when the watch ends); keeping the
robots' odometry at a bounded rate for the map; and raising alerts printed, stored and
published on ``/robotale/alerts``."""

from __future__ import annotations

import sys
import threading
import time
from pathlib import Path
from typing import TextIO

from robotale.discovery.online import pool_replays
from robotale.ekg.connection import session_driver
from robotale.ekg.growing import GrowingLog
from robotale.ekg.live import LiveLog
from robotale.fame_runtime.clock import WallClock
from robotale.fame_runtime.dds import DdsBus
from robotale.fame_runtime.launch import robot_list
from robotale.fame_runtime.processes import interrupts
from robotale.results.monitor import TICK, Monitor, alert_limits
from robotale.thresholds import LOW_BATTERY_PERCENT


def monitor_command(
    model: Path,
    *,
    log: str,
    robots: str | None = None,
    silence: float = 10.0,
    battery: float = LOW_BATTERY_PERCENT,
    message_timeout: list[str] | None = None,
    durations_from: list[str] | None = None,
    duration: float | None = None,
    out: TextIO | None = None,
    err: TextIO | None = None,
) -> int:
    """Watch the mission's robots until Ctrl-C or ``duration`` seconds, storing their tags
    as the live log ``log`` and alerting when one is silent longer than ``silence`` or its
    battery (``/<robot>/battery``) is below ``battery`` percent, a message is not received
    within its ``message_timeout`` (``[TYPE=]SECONDS`` texts) or an activity runs longer than
    the 95th percentile of its durations in the stored logs ``durations_from``."""
    out, err = out or sys.stdout, err or sys.stderr
    replays = pool_replays(model, robot_list(robots))
    deadline = time.monotonic() + duration if duration is not None else float("inf")
    stopped = threading.Event()
    with session_driver() as driver:
        limits = alert_limits(driver, silence, battery, message_timeout, durations_from)
        # refused here, before anything is stored, when --log names a log no monitor wrote
        graph = GrowingLog(driver, log)
        bus = DdsBus(WallClock(offset=0.0), node="monitor")
        try:
            monitor = Monitor(bus, LiveLog(driver, log), replays, limits, out, graph)
            # Ctrl-C or SIGTERM ends the watch between two tags, never inside a store
            with interrupts(stopped.set):
                print(
                    f"# monitoring {', '.join(replays)} as {log} (Ctrl-C stops)",
                    file=err,
                    flush=True,
                )
                while time.monotonic() < deadline and not stopped.is_set():
                    monitor.pump(min(TICK, max(0.0, deadline - time.monotonic())))
                bus.drain()
                monitor.pump(TICK)
                monitor.finish()
        finally:
            bus.close()
            graph.close()
    print(
        f"# {log}: {monitor.live.count} tags stored, {graph.events} events in its graph", file=err
    )
    return 0
