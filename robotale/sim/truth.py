"""A run's ground truth: what really happened, written beside the bag as ``robotale-truth.jsonl``.

The tags are what the robots *say* happened; the truth is what the simulator *knows*, taken
from the bus, the engines and the world rather than from the tags, so that every answer robotale
gives from a log can be checked against it. One JSON object per line, times in seconds since the
Unix epoch (simulated time, as the tags'):

- ``run``: the first line (``format``, ``case``, ``start``, ``robots``);
- ``send``: a message put on the bus (``t``, ``msg_id``, ``sender``, ``topic``, ``type``,
  ``payload``, ``reliability``);
- ``delivery``: what became of it for one subscriber (``t``, ``msg_id``, ``receiver``,
  ``outcome``: ``delivered``, ``qos``, ``fault``, ``loss``, ``busy``, ``left``, ``dead``); a
  message nobody subscribed to has none;
- ``activity``: one activity instance (``robot``, ``instance``, ``activity``, ``start``, ``end``,
  ``outcome``: ``completed``, ``interrupted``, ``cancelled``, ``died`` or ``running`` at the end);
- ``sample``: a robot's true pose and battery (``t``, ``robot``, ``x``, ``y``, ``z``,
  ``battery`` 0-1), ``record_rate`` times a second and once more as the run ends;
- ``death``: a robot died (``t``, ``robot``);
- ``end``: the run ended (``t``, ``status``).

``prepare`` never reads it: it is an oracle, not a source.
"""

from __future__ import annotations

import json
from collections.abc import Iterator, Mapping
from pathlib import Path
from typing import Any

from robotale.errors import InputError
from robotale.fame_runtime.bus import DELIVERED, LEFT, Envelope, InProcessBus, Subscription
from robotale.fame_runtime.clock import SimClock
from robotale.fame_runtime.engine import Engine
from robotale.fame_runtime.tags import TAG_TYPE
from robotale.files import atomic_file

#: the truth's file name inside a run's folder
TRUTH = "robotale-truth.jsonl"
FORMAT = 1
#: delivery outcomes the simulator adds to the bus's: a busy robot did not hear it
#: (``busy_ignores``); its receiver died before it arrived
BUSY, DEAD = "busy", "dead"


class Truth:
    """Collects one run's truth while it runs; :meth:`write` puts it beside the bag."""

    def __init__(self, clock: SimClock, case: str, robots: list[str]) -> None:
        self.clock = clock
        self.records: list[dict[str, Any]] = [
            {"kind": "run", "format": FORMAT, "case": case, "start": clock.now(), "robots": robots}
        ]
        self._running: dict[tuple[str, int], dict[str, Any]] = {}
        self._deliveries: dict[tuple[str, str], dict[str, Any]] = {}  # the last per receiver
        #: the robots that died, and when
        self.dead: dict[str, float] = {}
        #: when the robots were last sampled (None: never)
        self.sampled_at: float | None = None

    # -- what the bus, the engines and the world report ---------------------------------------

    def watch_bus(self, bus: InProcessBus) -> None:
        bus.tap(self._sent)
        bus.observer = self._delivery

    def watch_engines(self, engines: Mapping[str, Engine]) -> None:
        for engine in engines.values():
            engine.activity_observer = self._activity

    def _sent(self, envelope: Envelope) -> None:
        if not _message(envelope):
            return
        self.records.append(
            {
                "kind": "send",
                "t": envelope.stamp,
                "msg_id": envelope.msg_id,
                "sender": envelope.sender,
                "topic": envelope.topic,
                "type": envelope.msgtype,
                "payload": _plain(envelope.data),
                "reliability": envelope.qos.reliability,
            }
        )

    def _delivery(self, outcome: str, envelope: Envelope, subscription: Subscription) -> None:
        if not _message(envelope):
            return
        receiver = subscription.owner
        if outcome == LEFT and receiver in self.dead:
            outcome = DEAD
        record = {
            "kind": "delivery",
            "t": self.clock.now(),
            "msg_id": envelope.msg_id,
            "receiver": receiver,
            "topic": envelope.topic,
            "outcome": outcome,
        }
        self.records.append(record)
        self._deliveries[(envelope.msg_id, receiver)] = record

    def busy(self, robot: str, envelope: Envelope) -> None:
        """A busy robot did not hear a message the bus handed to it (``busy_ignores``)."""
        record = self._deliveries.get((envelope.msg_id, robot))
        if record is not None and record["outcome"] == DELIVERED:
            record["outcome"] = BUSY

    def _activity(self, robot: str, number: int, label: str, how: str) -> None:
        now = self.clock.now()
        if how == "start":
            record = {
                "kind": "activity",
                "robot": robot,
                "instance": number,
                "activity": label,
                "start": now,
                "end": None,
                "outcome": "running",
            }
            self._running[(robot, number)] = record
            self.records.append(record)
            return
        record = self._running.pop((robot, number), None)
        if record is not None:
            record["end"] = now
            record["outcome"] = "died" if robot in self.dead else how

    def died(self, robot: str) -> None:
        """``robot`` died now: its activities end unfinished, what is in flight to it is lost."""
        now = self.clock.now()
        self.dead[robot] = now
        self.records.append({"kind": "death", "t": now, "robot": robot})
        for (owner, _), record in list(self._running.items()):
            if owner == robot:
                record["end"], record["outcome"] = now, "died"

    def sample(self, robot: str, x: float, y: float, z: float, battery: float) -> None:
        self.sampled_at = self.clock.now()
        self.records.append(
            {
                "kind": "sample",
                "t": self.clock.now(),
                "robot": robot,
                "x": round(x, 4),
                "y": round(y, 4),
                "z": round(z, 4),
                "battery": round(battery, 5),
            }
        )

    def ended(self, status: str) -> None:
        now = self.clock.now()
        for record in self._running.values():
            record["end"] = now  # still running when the run ended: outcome stays "running"
        self._running.clear()
        self.records.append({"kind": "end", "t": now, "status": status})

    # -- the file ------------------------------------------------------------------------------

    def write(self, folder: Path) -> Path:
        path = folder / TRUTH
        with atomic_file(path) as file:
            for record in self.records:
                file.write(json.dumps(record, separators=(",", ":"), default=str) + "\n")
        return path


def read_truth(path: str | Path) -> Iterator[dict[str, Any]]:
    """The records of a truth file (a run folder, or the file itself), in order."""
    path = Path(path)
    if path.is_dir():
        path = path / TRUTH
    try:
        lines = path.read_text(encoding="utf-8").splitlines()
    except OSError as error:
        raise InputError(f"{path}: cannot read the run's truth ({error.strerror})") from None
    for number, line in enumerate(lines, 1):
        try:
            yield json.loads(line)
        except json.JSONDecodeError as error:
            raise InputError(f"{path}, line {number}: not JSON ({error.msg})") from None


def _message(envelope: Envelope) -> bool:
    """A message a mission sends (a signal or a BPMN message), not a tag or a sensor reading."""
    return bool(envelope.msg_id) and envelope.msgtype != TAG_TYPE


def _plain(data: Any) -> Any:
    """The payload as JSON holds it (dicts, lists, numbers, text)."""
    return json.loads(json.dumps(data, default=str))
