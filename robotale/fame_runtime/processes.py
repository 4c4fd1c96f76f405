"""A mission as one process per robot: ``fame run --bus dds`` starts a ``fame node`` process
for each robot, relays their tags and, when asked, records the domain meanwhile."""

from __future__ import annotations

import signal
import subprocess
import sys
import threading
import time
from collections.abc import Callable, Sequence
from contextlib import suppress
from pathlib import Path
from typing import IO, Protocol, TextIO

from robotale.fame_runtime.launch import robot_list, start_time
from robotale.fame_runtime.parser import parse
from robotale.fame_runtime.splitter import split

#: seconds a run waits for its robots beyond ``until`` before ending them
GRACE = 30.0


class Recording(Protocol):
    """What a run needs of a recording of the domain: time to write what arrives, a close."""

    def pump(self, seconds: float) -> None: ...

    def close(self, err: TextIO) -> None: ...


#: makes the recording of a run: given the robots' names and the clock's offset from now
RecordingFactory = Callable[[list[str], float], Recording]


class interrupts:
    """SIGINT and SIGTERM call ``handler`` instead of ending the process at once."""

    def __init__(self, handler: Callable[[], object]) -> None:
        self.handler = handler

    def __enter__(self) -> None:
        self.saved = {
            s: signal.signal(s, lambda *_: self.handler()) for s in (signal.SIGINT, signal.SIGTERM)
        }

    def __exit__(self, *exc: object) -> None:
        for number, saved in self.saved.items():
            signal.signal(number, saved)


def run_processes(
    model: Path,
    *,
    robots: str | None,
    skills: str | None,
    library: Path | None,
    until: float,
    assignments: Sequence[str],
    start: str | None,
    record: RecordingFactory | None,
    out: TextIO,
    err: TextIO,
) -> int:
    """``fame run --bus dds``: one ``fame node`` process per robot, their tags printed as
    they come, recorded with every other topic by the recording ``record`` makes, if given."""
    definitions = parse(model)
    names = [a.robot for a in split(definitions, robot_list(robots))]
    begin = start_time(start)
    offset = begin - time.time()
    recording = record(names, offset) if record is not None else None
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
        with interrupts(interrupted.set):
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


def _relay(stream: IO[str] | None, sink: TextIO) -> threading.Thread:
    lock = _SINK_LOCKS.setdefault(id(sink), threading.Lock())

    def copy() -> None:
        for line in stream or ():
            with lock:
                sink.write(line)
                sink.flush()

    thread = threading.Thread(target=copy, daemon=True)
    thread.start()
    return thread


_SINK_LOCKS: dict[int, threading.Lock] = {}


def _wait(
    children: Sequence[subprocess.Popen[str]],
    recording: Recording | None,
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
