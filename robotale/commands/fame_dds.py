"""``robotale fame node`` and ``robotale record``: one robot's engine as its own process over
Cyclone DDS, and rosbag2 recordings of live topics."""

from __future__ import annotations

import sys
import threading
import time
from collections.abc import Sequence
from pathlib import Path
from typing import TextIO

from robotale.errors import InputError
from robotale.fame_runtime.clock import WallClock
from robotale.fame_runtime.dds import DdsBus
from robotale.fame_runtime.launch import (
    instance_counts,
    parse_assignments,
    robot_list,
    start_time,
)
from robotale.fame_runtime.node import Node
from robotale.fame_runtime.parser import parse
from robotale.fame_runtime.processes import interrupts
from robotale.fame_runtime.skills import load_skills
from robotale.fame_runtime.tags import tag_line


def node_command(
    model: Path,
    *,
    robot: str,
    robots: str | None = None,
    skills: str | None = None,
    library: Path | None = None,
    until: float = 3600.0,
    assignments: Sequence[str] = (),
    start: str | None = None,
    wait: float = 30.0,
    clock_offset: float | None = None,
    origin: float | None = None,
    recorder: bool = False,
    out: TextIO | None = None,
    err: TextIO | None = None,
) -> int:
    """Run ``robot``'s engine in this process on DDS until the mission is over, printing its
    tags; 1 when an error went uncaught or the robot was still working at ``until``, 130
    after Ctrl-C (the robot's safe-state handler ran)."""
    out, err = out or sys.stdout, err or sys.stderr
    definitions = parse(model)
    if clock_offset is None:
        clock_offset = start_time(start) - time.time()
    clock = WallClock(offset=clock_offset)
    begin = clock.now() if origin is None else origin
    bus = DdsBus(clock, node=robot, on_warning=lambda text: print(f"# warning: {text}", file=err))
    node = Node(
        definitions,
        robot,
        bus=bus,
        robots=robot_list(robots),
        skills=load_skills(skills) if skills else None,
        library=library,
        variables=parse_assignments(assignments).get(robot),
        tag_sink=lambda tag: print(tag_line(tag, begin), file=out, flush=True),
        wait_for_recorder=recorder,
    )
    # a second Ctrl-C (a terminal's and fame run's own) must not cut the closing short
    with interrupts(node.interrupt):
        node.run(until=begin + until, wait=wait, warn=lambda text: print(f"# {text}", file=err))
        bus.close()
        return _node_verdict(node, begin, err)


def _node_verdict(node: Node, begin: float, err: TextIO) -> int:
    engine = node.engine
    if node.interrupted:
        state = "stopped (interrupted)"
    elif engine.idle:
        state = "done"
    else:
        state = "still running"
    reached = node.clock.now() - begin
    print(
        f"# {node.robot}: {state} at {reached:.3f} s; {instance_counts({node.robot: engine})}",
        file=err,
    )
    if not engine.idle:
        where = ", ".join(engine.where()) or "the start of an instance"
        print(f"# {node.robot} is at {where}", file=err)
    for failure in engine.failures:
        print(f"# {failure}", file=err)
    if node.interrupted:
        return 130
    return 1 if engine.failures or not engine.idle else 0


def record_command(
    out_dir: Path,
    *,
    robots: str,
    duration: float | None = None,
    err: TextIO | None = None,
) -> int:
    """Record every ROS-typed topic on the domain into a rosbag2 until Ctrl-C or
    ``duration`` seconds; ``robots`` names the robot namespaces (their tags, odometry ...)."""
    err = err or sys.stderr
    names = robot_list(robots)
    if not names:
        raise InputError("--robots names no robot (for example drone,tractor_1)")
    # A node process never records: the simulator's recorder (1.2 s to import) is loaded by a
    # recording only.
    from robotale.sim.live_recording import LiveRecording

    recording = LiveRecording(out_dir, names, 0.0)
    deadline = time.monotonic() + duration if duration is not None else float("inf")
    stopped = threading.Event()
    # Ctrl-C or SIGTERM ends a recording: the bag is closed whole below
    with interrupts(stopped.set):
        print(f"# recording {out_dir} (Ctrl-C stops)", file=err, flush=True)
        try:
            while time.monotonic() < deadline and not stopped.is_set():
                recording.pump(min(0.2, max(0.0, deadline - time.monotonic())))
        finally:
            recording.close(err)
    return 0
