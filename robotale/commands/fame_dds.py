"""``robotale fame node``, ``fame run --bus dds`` and ``robotale record``: missions as one
process per robot over Cyclone DDS, and rosbag2 recordings of live topics."""

from __future__ import annotations

import signal
import subprocess
import sys
import threading
import time
from collections.abc import Sequence
from contextlib import suppress
from pathlib import Path
from typing import TYPE_CHECKING, TextIO

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
from robotale.fame_runtime.skills import load_skills
from robotale.fame_runtime.splitter import split
from robotale.fame_runtime.tags import tag_line

if TYPE_CHECKING:
    from robotale.sim.live_recording import LiveRecording

#: seconds a run waits for its robots beyond ``until`` before ending them
GRACE = 30.0


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
    with _interrupts(node.interrupt):
        node.run(until=begin + until, wait=wait, warn=lambda text: print(f"# {text}", file=err))
        bus.close()
        return _node_verdict(node, begin, err)


class _interrupts:
    """SIGINT and SIGTERM call ``handler`` instead of ending the process at once."""

    def __init__(self, handler) -> None:
        self.handler = handler

    def __enter__(self) -> None:
        self.saved = {
            s: signal.signal(s, lambda *_: self.handler()) for s in (signal.SIGINT, signal.SIGTERM)
        }

    def __exit__(self, *exc) -> None:
        for number, saved in self.saved.items():
            signal.signal(number, saved)


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


def run_processes(
    model: Path,
    *,
    robots: str | None,
    skills: str | None,
    library: Path | None,
    until: float,
    assignments: Sequence[str],
    start: str | None,
    record: Path | None,
    out: TextIO,
    err: TextIO,
) -> int:
    """``fame run --bus dds``: one ``fame node`` process per robot, their tags printed as
    they come, recorded into a rosbag2 with every other topic when ``record`` is given."""
    definitions = parse(model)
    names = [a.robot for a in split(definitions, robot_list(robots))]
    begin = start_time(start)
    offset = begin - time.time()
    recording = _recording(record, names, offset) if record is not None else None
    command = [sys.executable, "-m", "robotale", "fame", "node", str(model)]
    command += ["--robots", ",".join(names), "--until", repr(until)]
    command += [f"--clock-offset={offset!r}", f"--origin={begin!r}"]
    for option, value in (("--skills", skills), ("--library", library)):
        if value is not None:
            command += [option, str(value)]
    for assignment in assignments:
        command += ["--set", assignment]
    if recording is not None:
        command.append("--wait-for-recorder")
    children = [
        subprocess.Popen(
            [*command, "--robot", robot], stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True
        )
        for robot in names
    ]
    relays = [_relay(c.stdout, out) for c in children] + [_relay(c.stderr, err) for c in children]
    # Ctrl-C (or SIGTERM) sets a flag: an exception could cut the recording mid-write
    interrupted = threading.Event()
    try:
        with _interrupts(interrupted.set):
            _wait(children, recording, time.monotonic() + until + GRACE, interrupted)
            if interrupted.is_set():
                for child in children:  # each robot runs its safe-state handler, then ends
                    with suppress(ProcessLookupError):
                        child.send_signal(signal.SIGINT)
                _wait(children, recording, time.monotonic() + GRACE)
    finally:
        for child in children:
            if child.poll() is None:
                child.kill()
                child.wait()
        for relay in relays:
            relay.join(timeout=5)
        if recording is not None:
            recording.close(err)
    # a child ended by a signal has a negative code: the shell's 128 + signal instead
    codes = [c.returncode if c.returncode >= 0 else 128 - c.returncode for c in children]
    return next((code for code in codes if code), 0)


def _relay(stream, sink: TextIO) -> threading.Thread:
    lock = _SINK_LOCKS.setdefault(id(sink), threading.Lock())

    def copy() -> None:
        for line in stream:
            with lock:
                sink.write(line)
                sink.flush()

    thread = threading.Thread(target=copy, daemon=True)
    thread.start()
    return thread


_SINK_LOCKS: dict[int, threading.Lock] = {}


def _wait(
    children,
    recording: LiveRecording | None,
    deadline: float,
    interrupted: threading.Event | None = None,
) -> None:
    """Until every child ended (or ``deadline``, or an interrupt), recording what arrives
    meanwhile."""
    while any(c.poll() is None for c in children) and time.monotonic() < deadline:
        if interrupted is not None and interrupted.is_set():
            return
        if recording is not None:
            recording.pump(0.05)
        else:
            time.sleep(0.05)


def _recording(path: Path, robots: list[str], offset: float) -> LiveRecording:
    # A node process never records: the simulator's recorder (1.2 s to import) is loaded by a
    # recording only.
    from robotale.sim.live_recording import LiveRecording

    return LiveRecording(path, robots, offset)


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
    recording = _recording(out_dir, names, 0.0)
    deadline = time.monotonic() + duration if duration is not None else float("inf")
    stopped = threading.Event()
    # Ctrl-C or SIGTERM ends a recording: the bag is closed whole below
    with _interrupts(stopped.set):
        print(f"# recording {out_dir} (Ctrl-C stops)", file=err, flush=True)
        try:
            while time.monotonic() < deadline and not stopped.is_set():
                recording.pump(min(0.2, max(0.0, deadline - time.monotonic())))
        finally:
            recording.close(err)
    return 0
