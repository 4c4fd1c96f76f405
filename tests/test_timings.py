"""Stage times on stderr (``ROBOTALE_TIMINGS``): the CPU printed is what the kernel counted."""

from __future__ import annotations

import os
import re
import resource
import time

from robotale import timings

LINE = re.compile(
    r"robotale timing: (?P<name>.+): (?P<wall>[\d.]+) s wall, (?P<cpu>[\d.]+) s CPU "
    r"\(\+ (?P<children>[\d.]+) s in subprocesses; Neo4j (?P<server>[\d.]+) s; load average"
)


def _busy(seconds: float) -> None:
    until = time.process_time() + seconds
    while time.process_time() < until:
        pass


def _own_cpu() -> float:
    usage = resource.getrusage(resource.RUSAGE_SELF)
    return usage.ru_utime + usage.ru_stime


def test_a_stage_prints_the_cpu_time_the_kernel_counted(monkeypatch, capsys):
    monkeypatch.setenv(timings.ENVIRONMENT, "1")
    # this process stands for the server: its CPU time, read from /proc, is counted twice
    monkeypatch.setattr(timings, "_server", [])
    timings.watch_server(os.getpid)
    before = _own_cpu()
    with timings.stage("a busy loop"):
        _busy(0.3)
    spent = _own_cpu() - before
    found = LINE.search(capsys.readouterr().err)
    assert found is not None and found["name"] == "a busy loop"
    assert abs(float(found["cpu"]) - spent) < 0.05
    assert abs(float(found["server"]) - spent) < 0.05  # /proc's clock ticks
    assert float(found["wall"]) >= float(found["cpu"]) - 0.01  # one thread
    assert float(found["children"]) == 0.0


def test_a_server_watched_within_a_stage_counts_from_then(monkeypatch, capsys):
    # the command's stage opens before the ingest names its server: the CPU the server spent
    # before (its start, earlier commands) is not this command's
    monkeypatch.setenv(timings.ENVIRONMENT, "1")
    monkeypatch.setattr(timings, "_server", [])
    monkeypatch.setattr(timings, "_watched_from", {})
    _busy(0.3)  # this process stands for the server: CPU spent before it is watched
    with timings.stage("the command"):
        timings.watch_server(os.getpid)
        before = _own_cpu()
        _busy(0.2)
        spent = _own_cpu() - before
    found = LINE.search(capsys.readouterr().err)
    assert found is not None
    assert abs(float(found["server"]) - spent) < 0.05


def test_nothing_is_printed_unless_asked(monkeypatch, capsys):
    monkeypatch.setenv(timings.ENVIRONMENT, "0")
    with timings.stage("quiet"):
        _busy(0.01)
    assert capsys.readouterr().err == ""
