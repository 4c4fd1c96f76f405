"""The true answers of a simulated batch, computed from the runs' truth files only.

This module reads ``robotale-truth.jsonl`` (docs/sim.md, *Ground truth*) with the standard
library and nothing of robotale: no tag, no event log, no analysis goes into its answers, so
they can judge robotale's findings.

Definitions (what "true" means here):

- a message is **delivered** when the bus handed it to at least one live subscriber of a robot
  (a catch event or a skill waiting for it); it is **lost** otherwise: dropped on the way, by a
  fault, by QoS, ignored by a busy robot, arrived after its receiver left or died, or nobody
  waited for it;
- its **latency** is the time from its publication to its first delivery; it is **delayed**
  when any of its deliveries took longer than a given threshold (a receiver got it late);
- a **resend** repeats an earlier send of the run (same sender, topic and payload: the
  generated missions' payloads name their task) on the sender's own account: a repeat that
  answers a message with that payload delivered to the sender in between (a worker answering
  a coordinator's resent question again) is an answer, not a resend;
- an activity instance's **duration** is its true interval; its **outcome** says whether it
  completed, was interrupted or cancelled, or its robot died;
- a robot's **battery use** in a run is the sum of the drops of its true battery level
  between consecutive samples, in percent (charging does not make it negative); over a
  window, the drops between the samples in it;
- two robots **met** when their true positions were within a distance in 3D at the same
  sample instant.
"""

from __future__ import annotations

import json
import math
from collections import Counter, defaultdict
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

TRUTH = "robotale-truth.jsonl"


@dataclass
class Run:
    """One run's truth, sorted by kind."""

    case: str
    start: float
    end: float
    robots: list[str]
    sends: list[dict[str, Any]] = field(default_factory=list)
    deliveries: list[dict[str, Any]] = field(default_factory=list)
    activities: list[dict[str, Any]] = field(default_factory=list)
    samples: list[dict[str, Any]] = field(default_factory=list)
    deaths: dict[str, float] = field(default_factory=dict)


def load(folder: str | Path) -> Run:
    """The truth of the run in ``folder`` (a run folder holding ``robotale-truth.jsonl``)."""
    records = [json.loads(line) for line in (Path(folder) / TRUTH).read_text().splitlines()]
    head = records[0]
    assert head["kind"] == "run", f"{folder}: the truth does not begin with its run"
    run = Run(head["case"], head["start"], head["start"], head["robots"])
    for record in records[1:]:
        kind = record["kind"]
        if kind == "send":
            run.sends.append(record)
        elif kind == "delivery":
            run.deliveries.append(record)
        elif kind == "activity":
            run.activities.append(record)
        elif kind == "sample":
            run.samples.append(record)
        elif kind == "death":
            run.deaths[record["robot"]] = record["t"]
        elif kind == "end":
            run.end = record["t"]
    return run


def load_batch(out: str | Path) -> list[Run]:
    """The truth of every run of a batch folder, in case order."""
    return [load(folder) for folder in sorted(Path(out).glob("run_*")) if (folder / TRUTH).exists()]


# -- messages ------------------------------------------------------------------------------------


@dataclass(frozen=True)
class Message:
    case: str
    msg_id: str
    sender: str
    topic: str
    sent: float
    receivers: tuple[str, ...]  # the robots it was delivered to
    latency: float | None  # to its first delivery
    slowest: float | None  # to its last delivery
    resend_of: str | None  # the earlier send it repeats
    drops: tuple[str, ...]  # why subscribers did not get it

    @property
    def delivered(self) -> bool:
        return bool(self.receivers)

    @property
    def type(self) -> str:
        return self.topic.strip("/")


def messages(run: Run) -> list[Message]:
    delivered: dict[str, list[tuple[float, str]]] = defaultdict(list)
    drops: dict[str, list[str]] = defaultdict(list)
    for delivery in run.deliveries:
        if delivery["outcome"] == "delivered":
            delivered[delivery["msg_id"]].append((delivery["t"], delivery["receiver"]))
        else:
            drops[delivery["msg_id"]].append(delivery["outcome"])
    payloads = {send["msg_id"]: _text(send["payload"]) for send in run.sends}
    heard: dict[str, list[tuple[float, str]]] = defaultdict(list)  # robot -> (time, payload)
    for delivery in run.deliveries:
        if delivery["outcome"] == "delivered":
            heard[delivery["receiver"]].append((delivery["t"], payloads[delivery["msg_id"]]))
    seen: dict[tuple, dict] = {}
    found = []
    for send in run.sends:
        key = (send["sender"], send["topic"], _text(send["payload"]))
        earlier = seen.get(key)
        answer = earlier is not None and any(
            earlier["t"] < t <= send["t"] and payload == key[2]
            for t, payload in heard[send["sender"]]
        )
        arrivals = sorted(delivered.get(send["msg_id"], ()))
        found.append(
            Message(
                run.case,
                send["msg_id"],
                send["sender"],
                send["topic"],
                send["t"],
                tuple(sorted({robot for _, robot in arrivals})),
                arrivals[0][0] - send["t"] if arrivals else None,
                arrivals[-1][0] - send["t"] if arrivals else None,
                None if earlier is None or answer else earlier["msg_id"],
                tuple(drops.get(send["msg_id"], ())),
            )
        )
        seen[key] = send
    return found


def _text(payload: Any) -> str:
    return json.dumps(payload, sort_keys=True)


def message_counts(runs: list[Run], delay: float) -> Counter:
    """sent, delivered, lost, delayed (latency above ``delay`` seconds) and resent."""
    counts: Counter = Counter()
    for run in runs:
        for message in messages(run):
            counts["sent"] += 1
            counts["delivered" if message.delivered else "lost"] += 1
            counts["delayed"] += message.slowest is not None and message.slowest > delay
            counts["resent"] += message.resend_of is not None
    return counts


# -- activities ----------------------------------------------------------------------------------


def activity_instances(runs: list[Run]) -> list[dict[str, Any]]:
    """Every activity instance: case, robot, activity, start, end, duration, outcome."""
    rows = []
    for run in runs:
        for activity in run.activities:
            end = activity["end"] if activity["end"] is not None else run.end
            rows.append(
                {
                    "case": run.case,
                    "robot": activity["robot"],
                    "activity": activity["activity"],
                    "start": activity["start"],
                    "end": end,
                    "duration": end - activity["start"],
                    "outcome": activity["outcome"],
                }
            )
    return rows


def activity_counts(runs: list[Run]) -> Counter:
    """Instances per (robot, activity), whatever their outcome (one its robot's death or the
    run's end cut short is an instance too)."""
    return Counter((row["robot"], row["activity"]) for row in activity_instances(runs))


def mean_durations(runs: list[Run]) -> dict[tuple[str, str], float]:
    """The mean true duration of the ended instances per (robot, activity), in seconds."""
    total: dict[tuple[str, str], list[float]] = defaultdict(list)
    for row in activity_instances(runs):
        if row["outcome"] in ("completed", "interrupted", "cancelled"):
            total[(row["robot"], row["activity"])].append(row["duration"])
    return {key: sum(values) / len(values) for key, values in total.items()}


def activity_effect(runs: list[Run], activity: str) -> float | None:
    """How much longer, in seconds, the runs in which ``activity`` ran lasted than the others
    (None when every run or none has it)."""
    with_it, without = [], []
    for run in runs:
        ran = any(a["activity"] == activity for a in run.activities)
        (with_it if ran else without).append(run.end - run.start)
    if not with_it or not without:
        return None
    return sum(with_it) / len(with_it) - sum(without) / len(without)


# -- battery and space ---------------------------------------------------------------------------


def battery_use(
    runs: list[Run], windows: dict[tuple[str, str], tuple[float, float]] | None = None
) -> dict[tuple[str, str], float]:
    """Percent of battery each robot used in each run (drops only; never summed over robots);
    with ``windows``, only between the two times given per (case, robot), and only for the
    robots given."""
    used: dict[tuple[str, str], float] = {}
    for run in runs:
        last: dict[str, float] = {}
        for sample in run.samples:
            robot, level = sample["robot"], sample["battery"] * 100.0
            key = (run.case, robot)
            if windows is not None:
                window = windows.get(key)
                if window is None or not window[0] <= sample["t"] <= window[1]:
                    continue
            used.setdefault(key, 0.0)
            if robot in last and level < last[robot]:
                used[key] += last[robot] - level
            last[robot] = level
    return used


def meetings(runs: list[Run], distance: float) -> Counter:
    """Per (case, robot, robot): how many sample instants the two were within ``distance``
    metres of each other in 3D."""
    met: Counter = Counter()
    for run in runs:
        by_time: dict[float, list[dict]] = defaultdict(list)
        for sample in run.samples:
            by_time[round(sample["t"], 3)].append(sample)
        for together in by_time.values():
            for i, a in enumerate(together):
                for b in together[i + 1 :]:
                    if a["robot"] == b["robot"]:
                        continue  # one robot sampled twice at one instant (the run's end)
                    apart = math.dist((a["x"], a["y"], a["z"]), (b["x"], b["y"], b["z"]))
                    if apart <= distance:
                        pair = tuple(sorted((a["robot"], b["robot"])))
                        met[(run.case, *pair)] += 1
    return met


def closest(runs: list[Run], seen=None) -> dict[tuple[str, str, str], float]:
    """Per (case, robot, robot): the smallest 3D distance between the two at one sample
    instant (with ``seen(case, robot, t)``, only at instants it accepts for both)."""
    nearest: dict[tuple[str, str, str], float] = {}
    for run in runs:
        by_time: dict[float, list[dict]] = defaultdict(list)
        for sample in run.samples:
            if seen is None or seen(run.case, sample["robot"], sample["t"]):
                by_time[round(sample["t"], 3)].append(sample)
        for together in by_time.values():
            for i, a in enumerate(together):
                for b in together[i + 1 :]:
                    if a["robot"] == b["robot"]:
                        continue  # one robot sampled twice at one instant (the run's end)
                    apart = math.dist((a["x"], a["y"], a["z"]), (b["x"], b["y"], b["z"]))
                    key = (run.case, *sorted((a["robot"], b["robot"])))
                    nearest[key] = min(apart, nearest.get(key, math.inf))
    return nearest


def flat_meetings(runs: list[Run], distance: float) -> Counter:
    """As :func:`meetings`, on the ground plan only (x, y): what a flat overlap would claim."""
    flattened = [
        Run(
            r.case,
            r.start,
            r.end,
            r.robots,
            samples=[{**s, "z": 0.0} for s in r.samples],
        )
        for r in runs
    ]
    return meetings(flattened, distance)
