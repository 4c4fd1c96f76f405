"""``robotale prepare`` and ``robotale ingest`` on bags without tags, from the command line.

Each test writes a recording of two robots (action goals, a mode topic, a behaviour-tree log,
tags without a lifecycle), keeps the plain facts it wrote, and computes from those the events
the log must hold; the log is read back from the CSV, or from Neo4j for ``ingest``.
"""

from __future__ import annotations

import json
import sqlite3
from dataclasses import dataclass, field

import numpy as np
import pandas as pd
import pytest
from bagbuilder import at, nanos
from rosbags.rosbag2 import StoragePlugin, Writer
from rosbags.typesys import Stores, get_types_from_msg, get_typestore

from robotale.cli import main
from robotale.results.findings import stored_timeline
from robotale.results.logdata import LogData

ACTION = "navigate_to_pose"
STATUS = f"/{{robot}}/{ACTION}/_action/status"
BT_CHANGE = "nav2_msgs/msg/BehaviorTreeStatusChange"
BT_LOG = "nav2_msgs/msg/BehaviorTreeLog"
BT_TYPES = {
    BT_CHANGE: "builtin_interfaces/Time timestamp\nstring node_name\nstring previous_status\n"
    "string current_status\n",
    BT_LOG: "builtin_interfaces/Time timestamp\nBehaviorTreeStatusChange[] event_log\n",
}
EVENT_TYPE = "my_msgs/msg/Event"
LOGGER = "rcl_interfaces/msg/LoggerLevel"  # a Jazzy type that Humble does not have
#: action_msgs/msg/GoalStatus codes that end a goal, and the lifecycle each must give
OUTCOMES = {4: "complete", 5: "cancelled", 6: "aborted"}
#: behaviour-tree statuses that end a RUNNING node, and the lifecycle each must give
BT_ENDS = {"SUCCESS": "complete", "FAILURE": "aborted", "IDLE": "cancelled"}
ROBOTS = ("r1", "r2")


@dataclass
class Recording:
    """Two robots' goals, modes, behaviour-tree nodes and plain events, drawn at random, as
    facts (for the expected events) and as messages (for the bag)."""

    seed: int = 1
    goals: list[tuple[str, float, int, float]] = field(default_factory=list)
    modes: list[tuple[str, float, str]] = field(default_factory=list)
    nodes: list[tuple[str, str, float, str, float]] = field(default_factory=list)
    events: list[tuple[str, float, str]] = field(default_factory=list)
    loggers: list[tuple[str, float, str]] = field(default_factory=list)

    def __post_init__(self) -> None:
        rng = np.random.default_rng(self.seed)
        for robot in ROBOTS:
            t = 1.0
            for _ in range(4):  # one goal after another, each ending before the next
                length = float(rng.integers(2, 8))
                self.goals.append((robot, t, int(rng.choice(list(OUTCOMES))), t + length))
                t += length + 1.5
            for k in range(12):  # repeated values are one activity
                self.modes.append((robot, 0.5 + 2 * k, str(rng.choice(["idle", "drive", "dock"]))))
            for k, node in enumerate(["ComputePath", "FollowPath", "Spin", "Wait"]):
                ended = 3.0 + 4 * k + float(rng.integers(1, 3))
                self.nodes.append((robot, node, 3.0 + 4 * k, str(rng.choice(list(BT_ENDS))), ended))
            for k in range(5):
                self.events.append((robot, 1.25 + 4.5 * k, str(rng.choice(["scan", "pick"]))))
            for k in range(3):
                self.loggers.append((robot, 2.0 + 7 * k, f"level_{k % 2}"))

    @property
    def end(self) -> float:
        """The time of the recording's last message: a goal's repeated outcome, or later."""
        return max(
            *(ended + 0.5 for *_, ended in self.goals),
            *(ended for *_, ended in self.nodes),
            *(when for facts in (self.modes, self.events, self.loggers) for _, when, _ in facts),
        )

    def messages(self, s) -> list[tuple[float, str, str, object]]:
        t = s.types
        out = []
        for robot, accepted, code, ended in self.goals:
            # the server says "executing" a little later, the outcome twice: only the first counts
            for when, status in ((accepted + 0.25, 2), (ended, code), (ended + 0.5, code)):
                out.append((when, STATUS.format(robot=robot), _status(s, robot, accepted, status)))
        for robot, when, mode in self.modes:
            out.append((when, f"/{robot}/mode", t["std_msgs/msg/String"](data=mode)))
        for robot, node, started, outcome, ended in self.nodes:
            for when, before, after in ((started, "IDLE", "RUNNING"), (ended, "RUNNING", outcome)):
                change = t[BT_CHANGE](
                    timestamp=_time(s, when), node_name=node, previous_status=before,
                    current_status=after,
                )  # fmt: skip
                log = t[BT_LOG](timestamp=_time(s, when), event_log=[change])
                out.append((when, f"/{robot}/behavior_tree_log", log))
        for robot, when, action in self.events:
            out.append((when, f"/{robot}/events", t[EVENT_TYPE](action=action)))
        for robot, when, name in self.loggers:
            out.append((when, f"/{robot}/logger", t[LOGGER](name=name, level=10)))
        return sorted(out, key=lambda m: m[0])

    def write(self, path, storage: str = "sqlite3", *, stored=None):
        """The bag; ``stored`` gives other definitions to store for some types."""
        s, stored = store(), stored or {}
        plugin = StoragePlugin.MCAP if storage == "mcap" else StoragePlugin.SQLITE3
        with Writer(path, version=9, storage_plugin=plugin) as writer:
            connections = {}
            for when, topic, message in self.messages(s):
                msgtype = message.__msgtype__
                if topic not in connections:
                    given = stored.get(msgtype)
                    own = {"msgdef": given, "rihs01": "RIHS01_" + "0" * 64} if given else {}
                    connections[topic] = writer.add_connection(
                        topic, msgtype, **(own or {"typestore": s})
                    )
                writer.write(connections[topic], nanos(when), s.serialize_cdr(message, msgtype))
        return path


def store():
    s = get_typestore(Stores.ROS2_JAZZY)
    for name, text in {**BT_TYPES, EVENT_TYPE: "string action\n"}.items():
        s.register(get_types_from_msg(text, name))
    return s


def _time(s, seconds: float):
    n = nanos(seconds)
    return s.types["builtin_interfaces/msg/Time"](sec=n // 10**9, nanosec=n % 10**9)


def _status(s, robot: str, accepted: float, code: int):
    t = s.types
    goal = int(accepted * 4) + (100 if robot == "r2" else 0)  # one id per goal
    info = t["action_msgs/msg/GoalInfo"](
        goal_id=t["unique_identifier_msgs/msg/UUID"](uuid=np.full(16, goal % 256, np.uint8)),
        stamp=_time(s, accepted),
    )
    entry = t["action_msgs/msg/GoalStatus"](goal_info=info, status=code)
    return t["action_msgs/msg/GoalStatusArray"](status_list=[entry])


# ------------------------------------------------------------ the events each source must give


def goal_events(r: Recording) -> list[tuple]:
    return [
        event
        for robot, accepted, code, ended in r.goals
        for event in (
            (at(accepted), ACTION, "start", robot),
            (at(ended), ACTION, OUTCOMES[code], robot),
        )
    ]


def runs(r: Recording, facts: list[tuple[str, float, str]]) -> list[tuple]:
    """Each robot's values as activities: a value lasts until another one (the last one until
    the end of the recording); a repeated value changes nothing."""
    events = []
    for robot in ROBOTS:
        mine = [(when, value) for who, when, value in facts if who == robot]
        starts = [
            (when, value)
            for k, (when, value) in enumerate(mine)
            if k == 0 or mine[k - 1][1] != value
        ]
        for k, (when, value) in enumerate(starts):
            until = starts[k + 1][0] if k + 1 < len(starts) else r.end
            events += [(at(when), value, "start", robot), (at(until), value, "complete", robot)]
    return events


def node_events(r: Recording) -> list[tuple]:
    return [
        event
        for robot, node, started, outcome, ended in r.nodes
        for event in (
            (at(started), node, "start", robot),
            (at(ended), node, BT_ENDS[outcome], robot),
        )
    ]


def implicit_events(r: Recording) -> list[tuple]:
    """Each event an activity until the robot's next one (the last until the end)."""
    events = []
    for robot in ROBOTS:
        mine = sorted((when, action) for who, when, action in r.events if who == robot)
        for k, (when, action) in enumerate(mine):
            until = mine[k + 1][0] if k + 1 < len(mine) else r.end
            events += [(at(when), action, "start", robot), (at(until), action, "complete", robot)]
    return events


def logged(csv) -> list[tuple]:
    log = pd.read_csv(csv)
    times = pd.to_datetime(log["time"], utc=True, format="ISO8601")
    return sorted(zip(times, log["activity"], log["lifecycle"], log["robot"], strict=True))


def prepare_cli(capsys, bag, out, *options: str) -> tuple[int, str]:
    code = main(
        ["prepare", str(bag), "--out", str(out), "--perspectives", "", "--rate", "0", *options]
    )
    return code, capsys.readouterr().err


# ------------------------------------------------------------------------------------- tests


@pytest.mark.parametrize("storage", ["sqlite3", "mcap"])
def test_actions_give_one_activity_per_goal_ended_by_its_outcome(tmp_path, capsys, storage):
    r = Recording(seed=2)
    bag = r.write(tmp_path / "run", storage)
    code, err = prepare_cli(capsys, bag, tmp_path / "log.csv", "--actions", "/*/_action/status")
    assert code == 0, err
    assert logged(tmp_path / "log.csv") == sorted(goal_events(r))
    assert len(r.goals) == 8 and {c for *_, c, _ in r.goals} > {4}  # more than successes
    # goal k of a robot is first seen in its status topic's message 3k, ended in 3k + 1
    text = pd.read_csv(tmp_path / "log.csv", dtype=str)
    assert sorted(zip(text["source_topic"], text["source_index"], strict=True)) == sorted(
        (STATUS.format(robot=robot), str(3 * k + end))
        for robot in ROBOTS
        for k in range(4)
        for end in (0, 1)
    )


def test_state_topics_give_one_activity_per_value(tmp_path, capsys):
    r = Recording(seed=3)
    bag = r.write(tmp_path / "run")
    code, err = prepare_cli(capsys, bag, tmp_path / "log.csv", "--state-topic", "/*/mode")
    assert code == 0, err
    assert logged(tmp_path / "log.csv") == sorted(runs(r, r.modes))
    # a second state topic, its field named
    code, err = prepare_cli(
        capsys, bag, tmp_path / "two.csv", "--state-topic", "/*/mode", "--state-topic",
        "/*/logger:name",
    )  # fmt: skip
    assert code == 0, err
    assert logged(tmp_path / "two.csv") == sorted(runs(r, r.modes) + runs(r, r.loggers))


def test_behaviour_tree_logs_give_one_activity_per_running_node(tmp_path, capsys):
    r = Recording(seed=4)
    bag = r.write(tmp_path / "run", "mcap")
    code, err = prepare_cli(capsys, bag, tmp_path / "log.csv", "--bt-log", "/*/behavior_tree_log")
    assert code == 0, err
    assert logged(tmp_path / "log.csv") == sorted(node_events(r))


def test_tags_without_lifecycle_become_activities_with_lifecycle_implicit(tmp_path, capsys):
    r = Recording(seed=5)
    bag = r.write(tmp_path / "run")
    fields = ["--tags", "/*/events", "--tag-field", "activity=action", "--tag-field", "lifecycle="]
    code, err = prepare_cli(capsys, bag, tmp_path / "log.csv", *fields, "--tag-field", "robot=",
                            "--lifecycle", "implicit")  # fmt: skip
    assert code == 0, err
    assert logged(tmp_path / "log.csv") == sorted(implicit_events(r))
    # without it, each tag is one event, and a warning says how to make them activities
    code, err = prepare_cli(capsys, bag, tmp_path / "events.csv", *fields, "--tag-field", "robot=")
    assert code == 0
    expected = [(at(when), action, "complete", robot) for robot, when, action in r.events]
    assert logged(tmp_path / "events.csv") == sorted(expected)
    assert "--lifecycle implicit makes each an activity" in err


@pytest.mark.parametrize("storage", ["sqlite3", "mcap"])
def test_auto_takes_actions_modes_and_bt_logs_and_says_so(tmp_path, capsys, storage):
    r = Recording(seed=6)
    bag = r.write(tmp_path / "run", storage)
    code, err = prepare_cli(capsys, bag, tmp_path / "log.csv", "--auto")
    assert code == 0, err
    expected = goal_events(r) + runs(r, r.modes) + node_events(r)
    assert logged(tmp_path / "log.csv") == sorted(expected)
    assert (
        "robotale: run: activities from --actions /*/_action/status, --state-topic "
        "/r1/mode:data, --state-topic /r2/mode:data, --bt-log "
        "/r1/behavior_tree_log|/r2/behavior_tree_log"
    ) in err


def without_definitions(bag):
    """The bag as ROS 2 Humble records it: no message definitions inside."""
    with sqlite3.connect(next(bag.glob("*.db3"))) as connection:
        connection.execute("DELETE FROM message_definitions")
    return bag


def test_distro_names_the_standard_types_of_a_bag_without_definitions(tmp_path, capsys):
    r = Recording(seed=7)
    bag = without_definitions(r.write(tmp_path / "run"))
    out = tmp_path / "log.csv"
    code, err = prepare_cli(
        capsys, bag, out, "--state-topic", "/*/logger:name", "--distro", "jazzy"
    )
    assert code == 0, err
    assert logged(out) == sorted(runs(r, r.loggers))
    out.unlink()
    code, err = prepare_cli(
        capsys, bag, out, "--state-topic", "/*/logger:name", "--distro", "humble"
    )
    assert code == 1 and not out.exists()
    assert err.splitlines()[-1] == (
        f"robotale: {bag}: cannot decode /r1/logger: the message type {LOGGER} is defined "
        "neither in the bag nor among the Humble types robotale knows; give its definition with "
        "--msg rcl_interfaces/msg/LoggerLevel.msg (a file at that path, or a folder holding "
        "rcl_interfaces/msg/LoggerLevel.msg)."
    )


def test_a_topic_that_cannot_be_decoded_is_one_sentence(tmp_path, capsys):
    r = Recording(seed=8)
    bag = r.write(tmp_path / "run", "mcap", stored={"std_msgs/msg/String": "uint32 data\n"})
    out = tmp_path / "log.csv"
    code, err = prepare_cli(capsys, bag, out, "--state-topic", "/*/mode")
    lines = [line for line in err.splitlines() if line.startswith("robotale: ")]
    assert code == 1 and not out.exists()
    # the stored uint32 takes a string's length for the value, and the rest is left over
    assert lines == [
        f"robotale: {bag}: a message on /r1/mode cannot be decoded as std_msgs/msg/String "
        f"(CDR message size mismatch for 'std_msgs/msg/String'); the definition "
        "registered for it does not match the recording (give the right one with --msg "
        "std_msgs/msg/String.msg, or the bag's distribution with --distro)."
    ]


def test_ingest_auto_stores_the_events_of_every_source(tmp_path, capsys, neo4j_driver, log_name):
    r = Recording(seed=9)
    bag = r.write(tmp_path / "run", "mcap")
    options = ["--auto", "--perspectives", "", "--rate", "0", "--log", log_name]
    code = main(["ingest", str(bag), *options])
    assert code == 0, capsys.readouterr().err
    records, _, _ = neo4j_driver.execute_query(
        "MATCH (e:Event {log: $log}) RETURN e.timestamp AS time, e.activity AS activity, "
        "e.lifecycle AS lifecycle, e.robot AS robot",
        log=log_name,
    )
    stored = sorted(
        (
            pd.Timestamp(x["time"].to_native()).tz_convert("UTC"),
            x["activity"],
            x["lifecycle"],
            x["robot"],
        )
        for x in records
    )
    assert stored == sorted(goal_events(r) + runs(r, r.modes) + node_events(r))
    # the dashboard's timeline says where each goal's events were recorded: goal k of a robot
    # is seen first in its status topic's message 3k and ends in 3k + 1 (numbered from 0)
    timeline = json.loads(stored_timeline(neo4j_driver, LogData(), log_name, "run"))
    bars = [t for t in timeline["figure"]["data"] if t["type"] == "bar" and t["name"] == ACTION]
    assert sorted(hover for bar in bars for _, hover in bar["customdata"]) == sorted(
        f"<br>from {STATUS.format(robot=robot)} #{3 * k} to #{3 * k + 1}"
        for robot in ROBOTS
        for k in range(4)
    )
