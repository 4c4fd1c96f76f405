"""Live robots over DDS watched by ``robotale monitor``: how long a tag takes to show on the
Mission page's data API, how fast the live run is stored, what the monitor costs per robot.

    python benchmarks/live.py [--robots 5 20 50] [--duration 60] [--per-process 5]
                              [--paint-events 10000] [--repeat 3] [--heap 1g] [--domain N]

Starts a private Neo4j (see ``ekg_build.py``) and Cyclone DDS on the loopback interface on a
domain of its own. For each number of robots: ``robotale monitor`` in its own process watches
``rover_1`` ... ``rover_N`` (a pool that surveys, measures and reports in a loop), while light
publisher processes (``--per-process`` robots each, plain ``cyclonedds`` writers with
robotale's message types) publish, for every robot, a tag every 1 to 2 s (starts and
completes of its activities, in the model's order, stamped with the wall clock) and odometry
(``nav_msgs/msg/Odometry`` on ``/<robot>/odom``) 10 times a second, for ``--duration``
seconds. Meanwhile this process asks the Mission page's data API, through Flask's test client
on the same Neo4j, what a following page asks, as the page asks it: the run's summary from a
little before the end it holds, waiting on the server until the run holds other events (a long
poll), then the positions and messages of that stretch and the state at the new end; again and
again.

Printed per robot count:

- the lag from a tag's stamp to the first answer of the API that shows it (its time among the
  summary's ``event_times``): p50 and p95, over the whole run and over its first and last
  thirds (by stamp), to show whether it grows; beside it, the baseline measured in the same
  run on the same tags: the lag to a plain ``cyclonedds`` reader in this process; the part of
  the lag before the monitor stored the tag (to the resolution of the counts taken before each
  look); the CPU time of this thread per look that found tags; then the
  lag per minute of stamps beside the load average and the machine's CPU (``/proc/stat``) in
  that minute, so growth over a long run shows, with the part before the monitor stored the
  tag and the CPU per look in each minute, and this process' CPU;
- the growth verdict (:func:`growth`): the lag's p95 over the last two whole minutes of stamps
  against minutes 2 and 3 (a ratio; the first minute is the start; "no growth" up to
  :data:`GROWTH_ALLOWED`), and the least-squares slope of the per-minute p95 from minute 2;
- the store's append rate: tags stored in Neo4j per second, against tags published per second;
- the monitor process' CPU (user + system) per robot, in % of one core;
- the check: the tags stored are the tags published (robot, activity, lifecycle, stamp).

The monitor subscribes to the odometry too and stores it at most 10 samples a second per
robot (as ``LivePose`` nodes, batched with the tags every tenth of a second), so the API's
looks read the positions as they grow as well.

Then the Mission page's first paint (its ``robotale-mission-shown`` mark: the first state drawn,
the map's robots and their table, before the timeline, model and plot, in headless Chromium
as the browser tests drive it, best of ``--repeat``) for one live run of ``--paint-events``
tags (20 robots' tags; the first ones appended one transaction each, as a monitor hearing a
tag at a time appends them, and that rate printed), against the same events stored as an
ordinary log (``build_ekg``), the baseline. Targets: lag p95 under 1 s at 20 robots for 10
minutes with no growth; first paint under 1 s at 10,000 events. The load average is printed
before and after.
"""

from __future__ import annotations

import argparse
import contextlib
import heapq
import json
import logging
import os
import random
import subprocess
import sys
import tempfile
import threading
import time
from collections import Counter
from collections.abc import Iterator
from pathlib import Path

from robotale.timings import process_seconds

BENCHMARKS = Path(__file__).resolve().parent
sys.path.insert(0, str(BENCHMARKS))

LOOPBACK = (
    '<CycloneDDS><Domain><General><Interfaces><NetworkInterface address="127.0.0.1"/>'
    "</Interfaces><AllowMulticast>false</AllowMulticast></General><Discovery>"
    "<ParticipantIndex>auto</ParticipantIndex><MaxAutoParticipantIndex>200"
    '</MaxAutoParticipantIndex><Peers><Peer address="127.0.0.1"/></Peers></Discovery>'
    "</Domain></CycloneDDS>"
)
#: the pool every benchmark robot runs: survey, measure, report, again or done
MODEL = """<?xml version="1.0" encoding="UTF-8"?>
<bpmn:definitions xmlns:bpmn="http://www.omg.org/spec/BPMN/20100524/MODEL" id="live_bench">
  <bpmn:collaboration id="collaboration">
    <bpmn:participant id="pool" name="Rover" processRef="rover">
      <bpmn:participantMultiplicity minimum="1" maximum="1000" />
    </bpmn:participant>
  </bpmn:collaboration>
  <bpmn:process id="rover" isExecutable="true">
    <bpmn:startEvent id="start" />
    <bpmn:task id="survey" name="survey" />
    <bpmn:task id="measure" name="measure" />
    <bpmn:task id="report" name="report" />
    <bpmn:exclusiveGateway id="again" default="loop" />
    <bpmn:endEvent id="end" />
    <bpmn:sequenceFlow id="f1" sourceRef="start" targetRef="survey" />
    <bpmn:sequenceFlow id="f2" sourceRef="survey" targetRef="measure" />
    <bpmn:sequenceFlow id="f3" sourceRef="measure" targetRef="report" />
    <bpmn:sequenceFlow id="f4" sourceRef="report" targetRef="again" />
    <bpmn:sequenceFlow id="loop" sourceRef="again" targetRef="survey" />
    <bpmn:sequenceFlow id="done" sourceRef="again" targetRef="end">
      <bpmn:conditionExpression>False</bpmn:conditionExpression>
    </bpmn:sequenceFlow>
  </bpmn:process>
</bpmn:definitions>
"""
ACTIVITIES = ("survey", "measure", "report")
ODOM_RATE = 10.0
#: seconds between two tags of one robot
TAG_GAP = (1.0, 2.0)
LAG_TARGET, PAINT_TARGET, PAINT_ROBOTS = 1.0, 1.0, 20
#: tags of the painted run appended as the monitor appends them, timed (the rest go faster)
TIMED_APPENDS = 500
#: seconds the monitor may go on storing after the last tag was published
CATCH_UP = 120.0
#: seconds before the end it holds a following page asks again from (the page's OVERLAP)
PAGE_OVERLAP = 5.0

#: a tag as published and as stored: robot, activity, lifecycle, stamp in microseconds
Key = tuple[str, str, str, int]


def robots_of(count: int) -> list[str]:
    return [f"rover_{i}" for i in range(1, count + 1)]


def tag_steps(robot: str, seed: int) -> Iterator[tuple[float, str, str]]:
    """(seconds after the previous tag, activity, lifecycle) of one robot, endlessly: starts
    and completes of its activities in the model's order, 1 to 2 s apart."""
    draw = random.Random(f"{seed}/{robot}")
    while True:
        for activity in ACTIVITIES:
            for lifecycle in ("start", "complete"):
                yield draw.uniform(*TAG_GAP), activity, lifecycle


def key(robot: str, activity: str, lifecycle: str, stamp: float) -> Key:
    return (robot, activity, lifecycle, round(stamp * 1e6))


def same_tags(published: list[Key], stored: list[Key]) -> tuple[list[Key], list[Key]]:
    """(published but not stored, stored but not published), each counted: the check that the
    monitor stored exactly what the robots sent. Stamps match within a microsecond (floats
    in Neo4j, rounded once on each side)."""
    left = Counter(published)
    extra = []
    for found in stored:
        robot, activity, lifecycle, micros = found
        near = [(robot, activity, lifecycle, micros + d) for d in (0, -1, 1)]
        match = next((k for k in near if left[k] > 0), None)
        if match is None:
            extra.append(found)
        else:
            left[match] -= 1
    return sorted(left.elements()), extra


def lags(stamps: dict[Key, float], seen: dict[Key, float]) -> list[tuple[float, float]]:
    """(stamp, seconds from the stamp to the first answer showing the tag) of every tag
    shown, in stamp order."""
    return sorted((stamps[k], seen[k] - stamps[k]) for k in stamps if k in seen)


def shown(published: list[Key], seen: dict[int, float]) -> dict[Key, float]:
    """When each published tag was first shown, from the first answer holding its stamp
    (microseconds since the epoch, as the run's start plus an offset rounded to the
    microsecond: within 2 of the published stamp)."""
    found = {}
    for tag in published:
        times = [seen[tag[3] + d] for d in (0, -1, 1, -2, 2) if tag[3] + d in seen]
        if times:
            found[tag] = min(times)
    return found


def quantiles(values: list[float]) -> tuple[float, float]:
    """p50 and p95 (numpy's linear percentiles; nan when there is nothing)."""
    import numpy as np

    if not values:
        return float("nan"), float("nan")
    p50, p95 = np.percentile(values, [50, 95])
    return float(p50), float(p95)


# -- the publishers ----------------------------------------------------------------------------


def publish(robots: list[str], seconds: float, seed: int, out: Path) -> None:
    """Publish the robots' tags and odometry on DDS for ``seconds``; write the tags sent."""
    from cyclonedds.domain import DomainParticipant
    from cyclonedds.pub import DataWriter
    from cyclonedds.topic import Topic
    from cyclonedds.util import duration

    from robotale.fame_runtime.dds import dds_qos
    from robotale.fame_runtime.node import KEEP_ALL
    from robotale.fame_runtime.qos import DEFAULT_QOS
    from robotale.fame_runtime.rostypes import dds_topic, idl_type, to_sample
    from robotale.fame_runtime.tags import TAG_TYPE, Tag, tag_topic

    odom_type = "nav_msgs/msg/Odometry"
    participant = DomainParticipant(int(os.environ["ROS_DOMAIN_ID"]))
    tag_idl, odom_idl = idl_type(TAG_TYPE), idl_type(odom_type)

    def writer(topic: str, idl, qos):
        return DataWriter(participant, Topic(participant, dds_topic(topic), idl), qos=dds_qos(qos))

    tags = {r: writer(tag_topic(r), tag_idl, KEEP_ALL) for r in robots}
    odoms = {r: writer(f"/{r}/odom", odom_idl, DEFAULT_QOS) for r in robots}
    time.sleep(3.0)  # discovery: the monitor's readers match before the first tag
    steps = {r: tag_steps(r, seed) for r in robots}
    pending = {r: next(steps[r])[1:] for r in robots}
    begin = time.time()
    # the robots' first tags spread over a second, as robots never start in step
    due = [(begin + random.Random(r).uniform(0, 1), r) for r in robots]
    heapq.heapify(due)
    sent = []
    tick, x = begin, 0.0
    while True:
        now = time.time()
        if now >= begin + seconds:
            break
        if due[0][0] <= now:
            _, robot = heapq.heappop(due)
            activity, lifecycle = pending[robot]
            stamp = time.time()
            tags[robot].write(to_sample(TAG_TYPE, Tag(stamp, robot, activity, lifecycle)))
            sent.append((robot, activity, lifecycle, stamp))
            gap, *pending_next = next(steps[robot])
            pending[robot] = tuple(pending_next)
            heapq.heappush(due, (stamp + gap, robot))
            continue
        if tick <= now:
            x += 0.05
            for robot in robots:
                odoms[robot].write(to_sample(odom_type, _odometry(robot, x, now)))
            tick += 1.0 / ODOM_RATE
            continue
        time.sleep(max(0.0, min(due[0][0], tick) - time.time()))
    deadline = time.time() + 10.0  # the tags acknowledged by the monitor before leaving
    for w in tags.values():
        with contextlib.suppress(Exception):
            w.wait_for_acks(duration(seconds=max(0.1, deadline - time.time())))
    out.write_text(json.dumps(sent))


def _odometry(robot: str, x: float, now: float) -> dict:
    seconds = int(now)
    return {
        "header": {
            "stamp": {"sec": seconds, "nanosec": int((now - seconds) * 1e9)},
            "frame_id": "odom",
        },
        "child_frame_id": f"{robot}/base_link",
        "pose": {"pose": {"position": {"x": x, "y": 0.0, "z": 0.0}}},
    }


# -- one measurement ---------------------------------------------------------------------------


class Baseline:
    """A plain cyclonedds reader of every robot's tags: when each tag reached this process."""

    def __init__(self, robots: list[str]) -> None:
        from cyclonedds.domain import DomainParticipant
        from cyclonedds.sub import DataReader
        from cyclonedds.topic import Topic

        from robotale.fame_runtime.dds import dds_qos
        from robotale.fame_runtime.node import KEEP_ALL
        from robotale.fame_runtime.rostypes import dds_topic, idl_type, to_data
        from robotale.fame_runtime.tags import TAG_TYPE, tag_topic

        participant = DomainParticipant(int(os.environ["ROS_DOMAIN_ID"]))
        idl = idl_type(TAG_TYPE)
        self.readers = [
            DataReader(
                participant, Topic(participant, dds_topic(tag_topic(r)), idl), qos=dds_qos(KEEP_ALL)
            )
            for r in robots
        ]
        self.seen: dict[Key, float] = {}
        self.decode = lambda sample: to_data(sample, TAG_TYPE)
        self.stop = threading.Event()
        self.thread = threading.Thread(target=self._take, daemon=True)
        self.thread.start()

    def _take(self) -> None:
        while not self.stop.is_set():
            for reader in self.readers:
                for sample in reader.take(N=256):
                    now = time.time()
                    if not sample.sample_info.valid_data:  # a writer that left
                        continue
                    tag = self.decode(sample)
                    self.seen.setdefault(
                        key(tag.robot, tag.activity, tag.lifecycle, tag.stamp), now
                    )
            time.sleep(0.005)

    def close(self) -> None:
        self.stop.set()
        self.thread.join()


def measure(
    count: int, seconds: float, per_process: int, folder: Path, client, driver, held_run: bool
) -> None:
    from robotale.ekg.live import delete_live, live_tags
    from robotale.results.live import live_builds, live_count

    robots = robots_of(count)
    name = f"bench_live_{count}"
    model = folder / "rover.bpmn"
    model.write_text(MODEL)
    monitor = subprocess.Popen(
        [sys.executable, "-m", "robotale", "monitor", str(model), "--robots", ",".join(robots),
         "--log", name, "--silence", "600"],
        stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True,
    )  # fmt: skip
    assert monitor.stderr.readline().startswith("# monitoring "), monitor.stderr.read()
    baseline = Baseline(robots)
    groups = [robots[i : i + per_process] for i in range(0, count, per_process)]
    outs = [folder / f"sent_{count}_{i}.json" for i in range(len(groups))]
    publishers = [
        subprocess.Popen(
            [
                sys.executable,
                __file__,
                "--publish",
                ",".join(group),
                "--duration",
                str(seconds),
                "--out",
                str(out),
            ]
        )
        for group, out in zip(groups, outs, strict=True)
    ]
    cpu_before, own_before = _cpu(monitor.pid), time.process_time()
    machine = Machine()
    began = time.time()
    seen: dict[Key, float] = {}
    looks: list[float] = []  # CPU seconds of this thread each look that found tags took
    looked: list[float] = []  # the wall time each of those looks ended
    waits: list[float] = []  # of which in the summary's request (its checks while waiting)
    counts: list[tuple[float, int]] = []  # (wall time, tags stored then)
    held: dict | None = None  # what the page holds: the run's length and number of events
    while any(p.poll() is None for p in publishers):
        counts.append((time.time(), live_count(driver, name)))
        cpu = time.thread_time()
        summary, waited = _look(client, name, held, held_run)
        if summary is None:  # no tag stored yet
            time.sleep(0.1)
            continue
        if held is not None and summary["events"] == held["events"]:
            continue  # the wait ran out: nothing new
        now = time.time()
        looks.append(time.thread_time() - cpu)
        looked.append(now)
        waits.append(waited)
        held = summary
        start = _epoch(summary["start"])
        for s in summary["event_times"]:
            seen.setdefault(round((start + s) * 1e6), now)
    ended = time.time()
    builds = live_builds(name)
    own = time.process_time() - own_before
    machine.close()
    sent = [tuple(t) for out in outs for t in json.loads(out.read_text())]
    caught_up = _catch_up(driver, name, len(sent), ended)
    cpu, cpu_wall = _cpu(monitor.pid) - cpu_before, time.time() - began
    monitor.terminate()
    monitor.communicate(timeout=60)
    baseline.close()
    published = [key(*t) for t in sent]
    stored = [key(t.robot, t.activity, t.lifecycle, t.stamp) for t in live_tags(driver, name)]
    missing, extra = same_tags(published, stored)
    delete_live(driver, name)
    stamps = {k: k[3] / 1e6 for k in published}
    api_lags = lags(stamps, shown(published, seen))
    dds_lags = lags(stamps, baseline.seen)
    span = max(stamps.values()) - min(stamps.values())
    asked = "of the run the summary showed" if held_run else "of the run as stored then"
    print(f"window and state asked {asked}: the run made {builds} times in "
          f"{len(looks)} looks that found tags")  # fmt: skip
    print(f"{count} robots, {span:.0f} s of tags, {len(published)} tags published "
          f"({len(published) / span:.1f}/s) and {count * ODOM_RATE * span:.0f} odometry "
          f"samples; {len(looks)} API looks that found tags (summary, window, state: "
          f"median {1000 * quantiles(looks)[0]:.0f} ms CPU each, p95 "
          f"{1000 * quantiles(looks)[1]:.0f} ms; the summary with its wait's checks median "
          f"{1000 * quantiles(waits)[0]:.0f} ms), load average "
          f"{os.getloadavg()[0]:.1f}")  # fmt: skip
    _print_lags("stamp -> Mission state API", api_lags, dds_lags)
    stored_lags = _stored_lags(published, stored, counts)
    s50, s95 = quantiles([lag for _, lag in stored_lags])
    print(f"  of which stamp -> stored by the monitor (seen by this process' count before "
          f"each look): p50 {s50:.3f} s, p95 {s95:.3f} s")  # fmt: skip
    _print_minutes(api_lags, machine, stored_lags, list(zip(looked, looks, strict=True)))
    _print_growth(api_lags)
    busy, load = machine.busy(began, ended), machine.load(began, ended)
    share = 100 * own / (ended - began)
    print(f"  this process (the API's looks and the plain reader): {share:.0f} % of a core "
          f"while publishing; the machine: {busy:.0f} % of its {os.cpu_count()} cores busy, "
          f"load average {load:.1f}")  # fmt: skip
    print(f"  store: {_rate(counts):.1f} tags/s appended while publishing; all "
          f"{len(stored)} of {len(published)} stored "
          f"{_caught(caught_up)} after the last was published")  # fmt: skip
    print(f"  monitor CPU: {100 * cpu / cpu_wall / count:.2f} % of a core per robot "
          f"({100 * cpu / cpu_wall:.1f} % in all, {cpu:.1f} s in {cpu_wall:.0f} s)")  # fmt: skip
    ok = not missing and not extra
    print(f"  check: tags stored == tags published: {'yes' if ok else 'NO'} "
          f"({len(missing)} missing, {len(extra)} extra)")  # fmt: skip


def _look(client, name: str, held: dict | None, held_run: bool) -> tuple[dict | None, float]:
    """One look of a page following the live run, as the Mission page makes it: the run's
    summary from a little before the end it holds (waiting on the server, up to a second
    here, until the run holds other events than it does), then the positions and messages
    of that stretch and the state at the new end. The summary (None when no tag is stored
    yet) and the CPU seconds of this thread its request took. With ``held_run``, the window
    and the state are asked of the run the summary showed (``?events=``), as the page asks."""
    api = f"/api/mission/{name}/{name}"
    cpu = time.thread_time()
    if held is None:
        answer = client.get(api)
        since = 0.0
    else:
        since = max(0.0, held["duration"] - PAGE_OVERLAP)
        answer = client.get(f"{api}?since={since}&known={held['events']}&wait=1")
    waited = time.thread_time() - cpu
    if answer.status_code != 200:
        return None, waited
    summary = answer.json
    if held is None or summary["events"] != held["events"]:
        events = f"&events={summary['events']}" if held_run else ""
        client.get(f"{api}/window?from={since}&to={summary['duration']}{events}")
        client.get(f"{api}/state?t={summary['duration']}{events}")
    return summary, waited


def _print_lags(what: str, measured: list[tuple[float, float]], baseline) -> None:
    values = [lag for _, lag in measured]
    p50, p95 = quantiles(values)
    b50, b95 = quantiles([lag for _, lag in baseline])
    third = len(measured) // 3
    f50, f95 = quantiles(values[:third])
    l50, l95 = quantiles(values[-third:] if third else [])
    verdict = "met" if p95 < LAG_TARGET else "MISSED"
    print(f"  lag {what}: p50 {p50:.3f} s, p95 {p95:.3f} s ({len(values)} tags; "
          f"target p95 < {LAG_TARGET:g} s: {verdict}); first third p50 {f50:.3f} / p95 "
          f"{f95:.3f} s, last third p50 {l50:.3f} / p95 {l95:.3f} s")  # fmt: skip
    print(f"  baseline, stamp -> plain cyclonedds reader: p50 {b50:.4f} s, p95 {b95:.4f} s "
          f"(the API's p95 is {p95 / b95:.0f}x)")  # fmt: skip


class Machine:
    """The load average and the machine's CPU (``/proc/stat``) sampled every few seconds, to
    print beside the lags of the same minutes."""

    EVERY = 2.0

    def __init__(self) -> None:
        self.samples: list[tuple[float, float, int, int]] = []  # time, load, busy, total ticks
        self.stop = threading.Event()
        self.thread = threading.Thread(target=self._sample, daemon=True)
        self.thread.start()

    def _sample(self) -> None:
        while True:
            fields = [int(v) for v in Path("/proc/stat").read_text().split("\n")[0].split()[1:]]
            idle = fields[3] + fields[4]  # idle and waiting for I/O
            self.samples.append((time.time(), os.getloadavg()[0], sum(fields) - idle, sum(fields)))
            if self.stop.wait(self.EVERY):
                return

    def close(self) -> None:
        self.stop.set()
        self.thread.join()

    def _between(self, start: float, end: float) -> list[tuple[float, float, int, int]]:
        return [s for s in self.samples if start <= s[0] <= end]

    def busy(self, start: float, end: float) -> float:
        """% of all cores busy from ``start`` to ``end`` (nan with fewer than two samples)."""
        inside = self._between(start, end)
        if len(inside) < 2:
            return float("nan")
        (_, _, b0, t0), (_, _, b1, t1) = inside[0], inside[-1]
        return 100 * (b1 - b0) / max(t1 - t0, 1)

    def load(self, start: float, end: float) -> float:
        """The mean 1-minute load average sampled from ``start`` to ``end``."""
        inside = self._between(start, end)
        return sum(s[1] for s in inside) / len(inside) if inside else float("nan")


def _print_minutes(
    measured: list[tuple[float, float]],
    machine: Machine,
    stored: list[tuple[float, float]],
    looks: list[tuple[float, float]],
) -> None:
    """The lag per minute of stamps, beside the part of it before the monitor stored the tag
    (by stamp too), the CPU of this thread per look that found tags (by the wall time the
    look ended) and the machine's load and CPU in that minute: a lag that grows with the run
    shows here, and whether the monitor's storing or the looks grow."""
    if not measured:
        return
    first = measured[0][0]
    minutes, stores, cpus = (
        _by_minute(measured, first),
        _by_minute(stored, first),
        _by_minute(looks, first),
    )
    for minute, values in sorted(minutes.items()):
        p50, p95 = quantiles(values)
        _, s95 = quantiles(stores.get(minute, []))
        c50, _ = quantiles(cpus.get(minute, []))
        start, end = first + 60 * minute, first + 60 * (minute + 1)
        print(f"    minute {minute + 1:2d}: lag p50 {p50:.3f} s, p95 {p95:.3f} s "
              f"({len(values)} tags); of which stored p95 {s95:.3f} s; look CPU median "
              f"{1000 * c50:.0f} ms; load average {machine.load(start, end):.1f}, CPU "
              f"{machine.busy(start, end):.0f} % busy")  # fmt: skip


def _by_minute(values: list[tuple[float, float]], first: float) -> dict[int, list[float]]:
    """The values of ``(time, value)`` pairs grouped by whole minutes since ``first``."""
    minutes: dict[int, list[float]] = {}
    for at, value in values:
        if at >= first:
            minutes.setdefault(int((at - first) // 60), []).append(value)
    return minutes


#: the lag's growth allowed before the verdict says it grows: the last two minutes' p95 at
#: most this much above the first two minutes'
GROWTH_ALLOWED = 1.10


def growth(measured: list[tuple[float, float]]) -> tuple[float, float] | None:
    """How the lag's p95 changes over the run: the p95 of the tags stamped in the last two
    whole minutes over that of minutes 2 and 3 (a ratio), and the least-squares slope of the
    per-minute p95 from minute 2 on, in seconds per minute; None for a run shorter than five
    whole minutes. The first minute holds the start (DDS discovery, the monitor's, the
    server's and the reader's first work) and a partial last minute the end: both are left
    out."""
    import numpy as np

    if not measured:
        return None
    first = measured[0][0]
    whole = int((measured[-1][0] - first) // 60)
    minutes = _by_minute([m for m in measured if m[0] < first + 60 * whole], first)
    if whole < 5 or any(m not in minutes for m in range(1, whole)):
        return None
    p95s = [quantiles(minutes[m])[1] for m in range(1, whole)]
    last = quantiles(minutes[whole - 2] + minutes[whole - 1])[1]
    ratio = last / quantiles(minutes[1] + minutes[2])[1]
    slope = float(np.polyfit(np.arange(len(p95s)), p95s, 1)[0])
    return ratio, slope


def _print_growth(measured: list[tuple[float, float]]) -> None:
    found = growth(measured)
    if found is None:
        print("  growth: not judged (fewer than five whole minutes of tags)")
        return
    ratio, slope = found
    verdict = "no growth" if ratio <= GROWTH_ALLOWED else "GROWS"
    print(f"  growth: p95 of the last two minutes / p95 of minutes 2-3 {ratio:.2f}x, per-minute "
          f"p95 slope from minute 2 {1000 * slope:+.1f} ms per minute (target no growth, at most "
          f"{GROWTH_ALLOWED:.2f}x: {verdict})")  # fmt: skip


def _stored_lags(published: list[Key], stored: list[Key], counts: list[tuple[float, int]]):
    """(stamp, seconds from it to the first count that held the tag) of each stored tag (the
    tags are numbered as stored), for the tags published: how late the monitor stores a tag, to the
    resolution of the counts."""
    import numpy as np

    times = np.array([t for t, _ in counts])
    held = np.maximum.accumulate(np.array([n for _, n in counts], dtype=np.int64))
    sent = {k[3] for k in published}
    firsts = np.searchsorted(held, np.arange(1, len(stored) + 1))
    return [
        (tag[3] / 1e6, times[first] - tag[3] / 1e6)
        for tag, first in zip(stored, firsts, strict=True)
        if tag[3] in sent and first < len(times)
    ]


def _catch_up(driver, name: str, published: int, since: float) -> float | None:
    """Seconds after ``since`` when the live run held all ``published`` tags (None when it
    still did not after :data:`CATCH_UP` seconds)."""
    from robotale.results.live import live_count

    while time.time() < since + CATCH_UP:
        if live_count(driver, name) >= published:
            return time.time() - since
        time.sleep(0.2)
    return None


def _caught(seconds: float | None) -> str:
    return f"within {seconds:.1f} s" if seconds is not None else f"NOT within {CATCH_UP:g} s"


def _rate(counts: list[tuple[float, int]]) -> float:
    """Tags stored per second between the first and the last count taken while publishing."""
    stored = [(t, n) for t, n in counts if n > 0]
    if len(stored) < 2:
        return float("nan")
    (t0, n0), (t1, n1) = stored[0], stored[-1]
    return (n1 - n0) / (t1 - t0)


def _cpu(pid: int) -> float:
    """User + system CPU seconds of process ``pid`` so far (0 when it is gone)."""
    return process_seconds(pid) or 0.0


def _epoch(iso: str) -> float:
    import pandas as pd

    return pd.Timestamp(iso).value / 1e9


# -- the Mission page's first paint ------------------------------------------------------------


def paint(driver, events: int, repeat: int, folder: Path) -> None:
    from playwright.sync_api import sync_playwright

    from robotale.ekg.live import LiveLog, delete_live
    from robotale.ekg.logs import delete_log
    from robotale.fame_runtime.tags import Tag
    from robotale.results.live import live_events
    from robotale.webapp import create_app
    from robotale.webapp.serve import Dashboard

    sys.path.insert(0, str(BENCHMARKS.parent / "tests" / "webapp"))
    from browser import launch, wait_for
    from dashboard import store

    name, stored = "bench_paint_live", "bench_paint_stored"
    live = LiveLog(driver, name)
    robots = robots_of(PAINT_ROBOTS)
    steps = {r: tag_steps(r, 1) for r in robots}
    clock = dict.fromkeys(robots, 1_800_000_000.0)
    tags = []
    while len(tags) < events:
        robot = robots[len(tags) % len(robots)]
        gap, activity, lifecycle = next(steps[robot])
        clock[robot] += gap
        tags.append(Tag(clock[robot], robot, activity, lifecycle))
    tags.sort(key=lambda t: t.stamp)
    timed = tags[:TIMED_APPENDS]
    began = time.perf_counter()
    for tag in timed:
        live.append(tag)
    spent = time.perf_counter() - began
    print(f"the monitor's store: {len(timed)} tags appended one transaction each in {spent:.1f} s:"
          f" {len(timed) / spent:.0f} tags/s (load average {os.getloadavg()[0]:.1f})")  # fmt: skip
    _append_rest(live, tags, len(timed))
    log = live_events(driver, name)
    log["case:concept:name"] = stored
    store(driver, stored, log)
    app = create_app(upload_dir=folder / "uploads", model_dir=folder / "models")
    logging.getLogger("werkzeug").setLevel(logging.WARNING)
    mark = "robotale-mission-shown"
    try:
        with Dashboard(app, port=0) as dashboard, sync_playwright() as playwright:
            context = launch(playwright, folder / "profile")
            page = context.new_page()
            page.goto(f"{dashboard.url}/cypher")  # the browser's cache of the scripts warm
            best = {}
            for _ in range(repeat):  # interleaved: stored, live, stored, live
                for which in (stored, name):
                    page.goto(f"{dashboard.url}/mission?log={which}&case={which}")
                    wait_for(page, f"performance.getEntriesByName('{mark}').length > 0",
                             timeout=600)  # fmt: skip
                    seconds = (
                        page.evaluate(f"performance.getEntriesByName('{mark}')[0].startTime") / 1000
                    )
                    best[which] = min(best.get(which, seconds), seconds)
            context.close()
    finally:
        delete_live(driver, name)
        delete_log(driver, stored)
    verdict = "met" if best[name] < PAINT_TARGET else "MISSED"
    print(f"Mission page first paint, {events:,}-event run (best of {repeat}): live "
          f"{best[name]:.2f} s, the same run stored as a log (baseline) {best[stored]:.2f} s "
          f"({best[name] / best[stored]:.2f}x; target < {PAINT_TARGET:g} s: "
          f"{verdict})")  # fmt: skip


def _append_rest(live, tags: list, done: int) -> None:
    """The tags after the first ``done`` stored as the monitor stores them (its query, the
    same numbering), a thousand to a transaction: the run to paint, built faster."""
    for first in range(done, len(tags), 1000):
        live.append_tags(tags[first : first + 1000])


# -- the whole benchmark -----------------------------------------------------------------------


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--robots", type=int, nargs="+", default=[5, 20])
    parser.add_argument("--duration", type=float, default=60.0, help="seconds per robot count")
    parser.add_argument("--per-process", type=int, default=5, help="robots per publisher")
    parser.add_argument("--paint-events", type=int, default=10_000)
    parser.add_argument("--repeat", type=int, default=3)
    parser.add_argument("--heap", default="1g")
    parser.add_argument(
        "--ask",
        choices=["held", "unheld", "both"],
        default="held",
        help="the window and state asked of the run the summary showed (held, as the page "
        "does), of the run as stored then (unheld, as the page did before), or both in turn",
    )
    parser.add_argument("--domain", type=int, default=150 + os.getpid() % 80)
    parser.add_argument("--publish", help=argparse.SUPPRESS)
    parser.add_argument("--out", type=Path, help=argparse.SUPPRESS)
    args = parser.parse_args()
    if args.publish:  # one publisher process, started by the benchmark
        publish(args.publish.split(","), args.duration, 1, args.out)
        return 0
    from dashboard import private_home
    from ekg_build import private_neo4j

    print(f"load average before: {os.getloadavg()[0]:.1f} on {os.cpu_count()} cores")
    with tempfile.TemporaryDirectory(prefix="robotale-bench-live-") as scratch, \
            private_home(), private_neo4j(args.heap) as driver:  # fmt: skip
        folder = Path(scratch)
        config = folder / "cyclonedds.xml"
        config.write_text(LOOPBACK)
        os.environ.update(CYCLONEDDS_URI=config.as_uri(), ROS_DOMAIN_ID=str(args.domain))
        from robotale.webapp import create_app

        app = create_app(upload_dir=folder / "uploads", model_dir=folder / "models")
        client = app.test_client()
        asks = [False, True] if args.ask == "both" else [args.ask == "held"]
        for count in args.robots:
            for held in asks:
                measure(count, args.duration, args.per_process, folder, client, driver, held)
        if args.paint_events:
            paint(driver, args.paint_events, args.repeat, folder)
    print(f"load average after: {os.getloadavg()[0]:.1f}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
