"""One known multi-robot execution, written as event logs in the conventions of several tools.

:func:`ground_truth` is what happened, as plain Python data: cases, robots with their types,
activity instances with their start and end, messages (sent, received, lost, resent under a
new id) and battery samples. The ``write_*`` functions render it as a file the way a tool
writes it, so a test can read the file back and compare with the truth:

- :func:`write_robotale_csv`: robotale's own CSV (short column names, ``inprogress`` rows with
  lifecycle ``none``, empty cells for no value, UTC times);
- :func:`write_inprogress_xes`: an XES whose starts say ``state=inprogress`` and completions
  ``state=done``, paired by ``execution_id``, ``null`` where there is no value, times at
  +02:00, samples without a lifecycle;
- :func:`write_robot_id_csv`: a CSV with ``robot_id`` (the instance) next to ``org:resource``
  (its type), ``msg_sender`` / ``msg_receiver`` instead of a role, ``concept:instance`` as the
  pairing key, and ``null``, ``-``, ``N/A``, ``None``, ``NaN`` and empty cells for no value;
  its battery is on the events, not in samples.

- :func:`write_thesis_csv`: the thesis' own CSV (``examples/thesis/robotic_data.csv``): no
  case column (runs are hours apart, so ``--case-gap 1h`` tells them apart), ``resource`` for
  the robot, ``msg_role`` on message events, a position on every event, times at +01:00, no
  battery and no samples.

The thesis' real recording is read as well in the tests; its truth is counted from the file.
"""

from __future__ import annotations

import csv
from dataclasses import dataclass, field
from pathlib import Path
from xml.sax.saxutils import quoteattr

import pandas as pd

DRONE, TRACTOR = "Drone", "Tractor"
ROBOTS = {"drone": DRONE, "tractor_1": TRACTOR, "tractor_2": TRACTOR}
CASE_STARTS = {"run1": "2023-06-01T09:00:00Z", "run2": "2023-06-02T14:30:00Z"}


@dataclass(frozen=True)
class Instance:
    """One execution of an activity by a robot; ``start == end`` for an instant event."""

    case: str
    robot: str
    activity: str
    start: pd.Timestamp
    end: pd.Timestamp
    key: str
    msg_id: str | None = None

    @property
    def seconds(self) -> float:
        return (self.end - self.start).total_seconds()

    @property
    def instant(self) -> bool:
        return self.start == self.end


@dataclass(frozen=True)
class Message:
    """A message from ``sender`` to ``receiver``; ``received`` is None when it was lost."""

    case: str
    msg_id: str
    topic: str
    sender: str
    receiver: str
    sent: pd.Timestamp
    received: pd.Timestamp | None
    resend_of: str | None = None


@dataclass(frozen=True)
class Sample:
    """A battery level measured while ``robot`` was doing ``activity``."""

    case: str
    robot: str
    activity: str
    time: pd.Timestamp
    battery: float


@dataclass
class GroundTruth:
    cases: list[str]
    robots: dict[str, str]
    instances: list[Instance] = field(default_factory=list)
    messages: list[Message] = field(default_factory=list)
    samples: list[Sample] = field(default_factory=list)

    def instance_table(self) -> pd.DataFrame:
        """case, robot, activity, start, end, seconds: one row per instance, sorted."""
        rows = [(i.case, i.robot, i.activity, i.start, i.end, i.seconds) for i in self.instances]
        columns = ["case", "robot", "activity", "start", "end", "seconds"]
        return pd.DataFrame(rows, columns=columns).sort_values(columns).reset_index(drop=True)

    def message_ids(self) -> set[str]:
        return {m.msg_id for m in self.messages}

    def events(self) -> list[dict]:
        """Every event the truth implies, in time order: starts and completes (an instant
        instance is one ``none`` event), then samples; each a dict of plain values."""
        rows = []
        for order, i in enumerate(self.instances):
            common = {"case": i.case, "robot": i.robot, "activity": i.activity, "key": i.key}
            common |= {"msg_id": i.msg_id, "order": order}
            common |= _message_ends(self, i)
            if i.instant:
                rows.append({**common, "time": i.end, "lifecycle": "none"})
            else:
                rows.append({**common, "time": i.start, "lifecycle": "start"})
                rows.append({**common, "time": i.end, "lifecycle": "complete"})
        for order, s in enumerate(self.samples, start=len(rows)):
            rows.append(
                {"case": s.case, "robot": s.robot, "activity": s.activity, "time": s.time}
                | {"lifecycle": "sample", "battery": s.battery, "order": order}
            )
        return sorted(rows, key=lambda row: (row["case"], row["time"], row["order"]))


class RunWriter:
    """Writes one run's activity instances and weed_position messages into a ground truth, at
    seconds after the run's beginning."""

    def __init__(self, truth: GroundTruth, case: str, begin: pd.Timestamp) -> None:
        self.truth, self.case, self.begin = truth, case, begin

    def at(self, seconds: float) -> pd.Timestamp:
        return self.begin + pd.Timedelta(seconds=seconds)

    def instance(self, robot: str, activity: str, start: float, end: float, msg_id=None) -> None:
        truth, case, at = self.truth, self.case, self.at
        key = f"{case}-{len(truth.instances) + 1}"
        truth.instances.append(Instance(case, robot, activity, at(start), at(end), key, msg_id))

    def message(self, number: int, to: str, sent: float, received: float | None, resend_of=None):
        """A weed_position from the drone to ``to``, lost when ``received`` is None."""
        msg_id = f"{self.case}-m{number}"
        got = self.at(received) if received is not None else None
        self.truth.messages.append(
            Message(self.case, msg_id, "weed_position", "drone", to, self.at(sent), got, resend_of)
        )
        self.instance("drone", "weed_position!", sent, sent + 1, msg_id)
        if received is not None:
            self.instance(to, "weed_position?", received, received + 0.5, msg_id)
        return msg_id


def busy_seconds(intervals: pd.DataFrame) -> float:
    """Seconds covered by the union of [start, end] intervals (one robot in one case)."""
    total, reach = 0.0, None
    ordered = intervals.sort_values(["start", "end"])[["start", "end"]]
    for start, end in ordered.itertuples(index=False):
        if reach is None or start > reach:
            total += (end - start).total_seconds()
            reach = end
        elif end > reach:
            total += (end - reach).total_seconds()
            reach = end
    return total


def _message_ends(truth: GroundTruth, instance: Instance) -> dict:
    """Sender, receiver and role of a message activity's events (nothing for others)."""
    if instance.msg_id is None:
        return {}
    message = next(m for m in truth.messages if m.msg_id == instance.msg_id)
    role = "send" if instance.activity.endswith("!") else "receive"
    return {"sender": message.sender, "receiver": message.receiver, "role": role}


def battery(robot: str, case: str, time: pd.Timestamp) -> float:
    """The battery level the truth gives ``robot`` at ``time``: draining linearly per run."""
    drain = {"drone": 0.25, "tractor_1": 0.1, "tractor_2": 0.05}[robot]
    return round(100.0 - drain * (time - pd.Timestamp(CASE_STARTS[case])).total_seconds(), 3)


def ground_truth() -> GroundTruth:
    """Two runs on different days of a drone and two tractors.

    In each run the drone scans twice with the second scan nested in the first (only a
    pairing key pairs them right), sends a weed position to tractor_1, sends one to tractor_2
    that is lost and resends it under a new id; tractor_2 waits until it receives it;
    tractor_1 raises a low_battery instant event.
    """
    truth = GroundTruth(cases=list(CASE_STARTS), robots=dict(ROBOTS))
    for case, begin in CASE_STARTS.items():
        _one_run(truth, case, pd.Timestamp(begin))
    return truth


def _one_run(truth: GroundTruth, case: str, begin: pd.Timestamp) -> None:
    run = RunWriter(truth, case, begin)
    at, instance, message = run.at, run.instance, run.message

    instance("drone", "takeoff", 0, 5)
    instance("drone", "explore", 5, 40)
    instance("drone", "scan", 10, 30)
    instance("drone", "scan", 12, 18)
    instance("tractor_2", "wait", 0, 46)
    message(1, "tractor_1", 20, 21.5)
    lost = message(2, "tractor_2", 30, None)
    message(3, "tractor_2", 45, 46.5, resend_of=lost)
    instance("tractor_1", "move_to_weed", 22, 50)
    instance("tractor_1", "low_battery", 48, 48)
    instance("tractor_2", "move_to_weed", 47, 70)
    instance("drone", "land", 60, 64)
    for robot, activity, seconds in (
        ("drone", "explore", (10, 20, 30)),
        ("tractor_1", "move_to_weed", (30, 40)),
        ("tractor_2", "wait", (10, 20, 30, 40)),
        ("tractor_2", "move_to_weed", (50, 60)),
    ):
        for second in seconds:
            time = at(second)
            truth.samples.append(Sample(case, robot, activity, time, battery(robot, case, time)))


# -- renderings --------------------------------------------------------------------------------


def write_robotale_csv(truth: GroundTruth, path: Path) -> Path:
    """robotale's own CSV, as ``robotale prepare`` writes it."""
    header = ["case", "time", "activity", "lifecycle", "state", "robot", "robot_type"]
    header += ["msg_id", "msg_role", "msg_payload", "battery", "event_id", "execution_id"]
    rows = []
    for number, event in enumerate(truth.events()):
        sample = event["lifecycle"] == "sample"
        rows.append(
            [
                event["case"],
                _utc(event["time"]),
                event["activity"],
                "none" if sample else event["lifecycle"],
                "inprogress" if sample else "none",
                event["robot"],
                truth.robots[event["robot"]],
                event.get("msg_id") or "",
                event.get("role", ""),
                "weed at 3,4" if event.get("msg_id") else "",
                event.get("battery", ""),
                f"e{number}",
                "" if sample else event["key"],
            ]
        )
    return _write_csv(path, header, rows)


def write_inprogress_xes(truth: GroundTruth, path: Path) -> Path:
    """An XES of a tool that says ``state=inprogress`` on every start and ``done`` on every
    completion, writes ``null`` for no value, and records samples without a lifecycle."""
    traces = []
    for case in truth.cases:
        events = [_xes_event(truth, e) for e in truth.events() if e["case"] == case]
        traces.append(
            f'  <trace>\n    <string key="concept:name" value="{case}"/>\n'
            + "".join(events)
            + "  </trace>\n"
        )
    path.write_text(
        '<?xml version="1.0" encoding="UTF-8"?>\n'
        '<log xes.version="1.0" xmlns="http://www.xes-standard.org/">\n'
        + "".join(traces)
        + "</log>\n",
        encoding="utf-8",
    )
    return path


def _xes_event(truth: GroundTruth, event: dict) -> str:
    sample = event["lifecycle"] == "sample"
    attributes = [("string", "concept:name", event["activity"])]
    if not sample:
        # an instant event is a completion without a start in this tool's logs
        transition = "start" if event["lifecycle"] == "start" else "complete"
        attributes.append(("string", "lifecycle:transition", transition))
    state = "inprogress" if sample or event["lifecycle"] == "start" else "done"
    attributes += [
        ("string", "state", state),
        ("string", "org:resource", event["robot"]),
        ("string", "org:role", truth.robots[event["robot"]]),
        ("string", "execution_id", "null" if sample else event["key"]),
        ("string", "msg_id", event.get("msg_id") or "null"),
        ("float", "battery", event["battery"] if sample else "NaN"),
        ("date", "time:timestamp", event["time"].tz_convert("+02:00").isoformat()),
    ]
    lines = "".join(
        f"      <{kind} key={quoteattr(key)} value={quoteattr(str(value))}/>\n"
        for kind, key, value in attributes
    )
    return f"    <event>\n{lines}    </event>\n"


#: the markers the robot_id CSV writes for "no battery reading", in turn.
BATTERY_MARKERS = ("NaN", "None", "N/A", "-")


def write_robot_id_csv(truth: GroundTruth, path: Path) -> Path:
    """A CSV with ``robot_id`` and ``org:resource`` (the type), message senders and receivers,
    and a different marker for "no value" in nearly every column. Every third event has no
    battery reading (one of :data:`BATTERY_MARKERS`); an instant event has an empty
    lifecycle."""
    header = ["case_id", "timestamp", "robot_id", "org:resource", "activity"]
    header += ["lifecycle:transition", "concept:instance", "msg_id", "msg_sender"]
    header += ["msg_receiver", "battery"]
    rows = []
    events = [e for e in truth.events() if e["lifecycle"] != "sample"]
    for number, event in enumerate(events):
        reading = battery(event["robot"], event["case"], event["time"])
        missing = BATTERY_MARKERS[(number // 3) % len(BATTERY_MARKERS)]
        rows.append(
            [
                event["case"],
                event["time"].tz_convert("UTC").strftime("%Y-%m-%d %H:%M:%S.%f")[:-3],
                event["robot"],
                truth.robots[event["robot"]],
                event["activity"],
                "" if event["lifecycle"] == "none" else event["lifecycle"],
                event["key"],
                event.get("msg_id") or "null",
                event.get("sender", "-"),
                event.get("receiver", ""),
                missing if number % 3 == 2 else reading,
            ]
        )
    return _write_csv(path, header, rows)


#: where each robot is on every event of :func:`write_thesis_csv` (x, y, z)
THESIS_POSITIONS = {
    "drone": (2.0, 8.0, 1.5),
    "tractor_1": (1.0, 1.0, 0.0),
    "tractor_2": (9.0, 1.0, 0.0),
}


def write_thesis_csv(truth: GroundTruth, path: Path) -> Path:
    """The thesis' CSV: one file of all runs without a case column, every event a start or a
    complete (an instant event a lone complete), as its recorder writes them."""
    header = ["time", "activity", "lifecycle", "msg_id", "msg_payload", "msg_role"]
    header += ["x", "y", "z", "field", "resource", "event_id"]
    rows = []
    events = [e for e in truth.events() if e["lifecycle"] != "sample"]
    for number, event in enumerate(sorted(events, key=lambda e: (e["time"], e["order"]))):
        message = event.get("msg_id")
        rows.append(
            [
                event["time"].tz_convert("+01:00").isoformat(timespec="milliseconds"),
                event["activity"],
                "complete" if event["lifecycle"] == "none" else event["lifecycle"],
                message or "",
                "weed at 3,4" if message else "",
                event.get("role", ""),
                *THESIS_POSITIONS[event["robot"]],
                "f1",
                event["robot"],
                f"e{number}",
            ]
        )
    return _write_csv(path, header, rows)


def robot_id_battery(truth: GroundTruth) -> list[float | None]:
    """The battery column :func:`write_robot_id_csv` writes, None where it writes a marker."""
    events = [e for e in truth.events() if e["lifecycle"] != "sample"]
    return [
        None if number % 3 == 2 else battery(e["robot"], e["case"], e["time"])
        for number, e in enumerate(events)
    ]


def _utc(time: pd.Timestamp) -> str:
    return time.tz_convert("UTC").strftime("%Y-%m-%dT%H:%M:%S.%f")[:-3] + "Z"


def _write_csv(path: Path, header: list[str], rows: list[list]) -> Path:
    with path.open("w", newline="", encoding="utf-8") as file:
        writer = csv.writer(file)
        writer.writerow(header)
        writer.writerows(rows)
    return path
