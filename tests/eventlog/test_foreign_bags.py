"""ROS 2 recordings that robotale did not write: a Nav2-style navigation without tags.

The bags are written with rosbags' writer in each storage and with the metadata each of
Humble, Iron and Jazzy writes; the expected events are written out by hand.
"""

from __future__ import annotations

import warnings

import numpy as np
import pytest
import yaml
from bagbuilder import at, nanos
from rosbags.interfaces import Qos, QosDurability, QosHistory, QosLiveliness, QosTime
from rosbags.interfaces import QosReliability as Reliability
from rosbags.rosbag2 import Reader, StoragePlugin, Writer
from rosbags.typesys import Stores, get_types_from_msg, get_typestore

from robotale.errors import InputError
from robotale.eventlog.enrich import PreparationWarning
from robotale.eventlog.prepare import TagFields, prepare
from robotale.eventlog.rosbag import read_bag
from robotale.sim import bagmeta

STATUS = "/r1/navigate_to_pose/_action/status"
EVENT_TYPE, EVENT_DEF = "my_msgs/msg/Event", "string action\n"
SERVICE_EVENT = "test_msgs/srv/BasicTypes_Event"
#: what rosbag2 (Jazzy) stores for a service-event topic: the service's .srv text
SERVICE_DEF = (
    "=" * 80 + "\nSRV: test_msgs/srv/BasicTypes\nbool bool_value\nstring string_value\n---\n"
    "bool bool_value\nstring string_value\n"
)
COLUMNS = ["time:timestamp", "concept:name", "lifecycle:transition", "robot"]
NO_TIME = QosTime(0, 0)


def qos(reliability: Reliability) -> Qos:
    return Qos(
        QosHistory.KEEP_LAST, 10, reliability, QosDurability.VOLATILE, NO_TIME, NO_TIME,
        QosLiveliness.AUTOMATIC, NO_TIME, False,
    )  # fmt: skip


class Nav2Bag:
    """Goals on navigate_to_pose (succeeded, aborted, cancelled), a mode topic, tags without a
    lifecycle, a service-event topic and /rosout, for one robot r1 over 10 s."""

    def __init__(self) -> None:
        self.store = get_typestore(Stores.ROS2_HUMBLE)
        self.store.register(get_types_from_msg(EVENT_DEF, EVENT_TYPE))
        self.messages: list[tuple[float, str, str, object]] = []
        goals = {"g1": 1, "g2": 2, "g3": 3}
        # (time, [(goal, status code, accepted at)]) as an action server publishes them
        for t, statuses in (
            (1, [("g1", 1, 1.0)]),
            (2, [("g1", 2, 1.0)]),
            (5, [("g1", 4, 1.0)]),
            (6, [("g1", 4, 1.0), ("g2", 2, 5.5)]),
            (8, [("g2", 6, 5.5)]),
            (9, [("g3", 2, 9.0)]),
            (9.5, [("g3", 3, 9.0)]),
            (10, [("g3", 5, 9.0)]),
        ):
            self.status(t, [(goals[g], code, accepted) for g, code, accepted in statuses])
        for t, mode in ((0, "idle"), (1, "navigating"), (3, "navigating"), (5, "idle")):
            self.add(t, "/r1/mode", "std_msgs/msg/String", self.t["std_msgs/msg/String"](data=mode))
        for t, action in ((0.5, "boot"), (4, "check")):
            self.add(t, "/r1/events", EVENT_TYPE, self.t[EVENT_TYPE](action=action))
        log = self.t["rcl_interfaces/msg/Log"](
            stamp=self.time(3), level=20, name="nav", msg="planning", file="f.cpp",
            function="plan", line=7,
        )  # fmt: skip
        self.add(3, "/rosout", "rcl_interfaces/msg/Log", log)

    @property
    def t(self):
        return self.store.types

    def time(self, seconds: float):
        n = nanos(seconds)
        return self.t["builtin_interfaces/msg/Time"](sec=n // 10**9, nanosec=n % 10**9)

    def add(self, seconds, topic, msgtype, message):
        self.messages.append((seconds, topic, msgtype, message))

    def status(self, seconds, statuses):
        t = self.t
        entries = [
            t["action_msgs/msg/GoalStatus"](
                goal_info=t["action_msgs/msg/GoalInfo"](
                    goal_id=t["unique_identifier_msgs/msg/UUID"](uuid=np.full(16, goal, np.uint8)),
                    stamp=self.time(accepted),
                ),
                status=code,
            )
            for goal, code, accepted in statuses
        ]
        message = t["action_msgs/msg/GoalStatusArray"](status_list=entries)
        self.add(seconds, STATUS, "action_msgs/msg/GoalStatusArray", message)

    def write(
        self, path, storage="sqlite3", distro="jazzy", *, definitions=None, qos_of=None,
        service_def=SERVICE_DEF,
    ):  # fmt: skip
        """The bag; ``definitions`` overrides what is stored for a type, ``qos_of`` maps topics
        to the QoS metadata.yaml gives them (the storage keeps the default)."""
        definitions = definitions or {}
        plugin = StoragePlugin.MCAP if storage == "mcap" else StoragePlugin.SQLITE3
        with Writer(path, version=bagmeta.writer_version(distro), storage_plugin=plugin) as w:
            connections = {}
            for seconds, topic, msgtype, message in sorted(self.messages, key=lambda m: m[0]):
                if topic not in connections:
                    stored = definitions.get(msgtype)
                    connections[topic] = w.add_connection(
                        topic, msgtype, offered_qos_profiles=[qos(Reliability.RELIABLE)],
                        **({"msgdef": stored, "rihs01": "RIHS01_" + "0" * 64} if stored is not None
                           else {"typestore": self.store}),
                    )  # fmt: skip
                data = self.store.serialize_cdr(message, msgtype)
                w.write(connections[topic], nanos(seconds), data)
            service = w.add_connection(
                "/r1/get_plan/_service_event", SERVICE_EVENT,
                msgdef=service_def,
                rihs01="RIHS01_" + "1" * 64,
            )  # fmt: skip
            for seconds, kind in ((2, 0), (2.5, 3)):  # a request sent, its response received
                w.write(service, nanos(seconds), service_event(kind, seconds))
        bagmeta.for_distro(path, distro)
        if qos_of:
            _set_qos(path, qos_of)
        return path


def service_event(kind: int, seconds: float) -> bytes:
    """A BasicTypes service event's bytes, serialized by rosbags under stand-in names (CDR
    holds no names, and rosbags' parser knows no ``srv`` folder)."""
    store = get_typestore(Stores.ROS2_JAZZY)
    store.register(get_types_from_msg("bool bool_value\nstring string_value\n", "sv/msg/Part"))
    store.register(
        get_types_from_msg(
            "service_msgs/ServiceEventInfo info\nsv/Part[<=1] request\nsv/Part[<=1] response\n",
            "sv/msg/Event",
        )
    )
    t, n = store.types, nanos(seconds)
    info = t["service_msgs/msg/ServiceEventInfo"](
        event_type=kind, stamp=t["builtin_interfaces/msg/Time"](sec=n // 10**9, nanosec=n % 10**9),
        client_gid=np.arange(16, dtype=np.uint8), sequence_number=7,
    )  # fmt: skip
    part = [t["sv/msg/Part"](bool_value=True, string_value="plan")]
    event = t["sv/msg/Event"](
        info=info, request=part if kind == 0 else [], response=part if kind == 3 else []
    )
    return bytes(store.serialize_cdr(event, "sv/msg/Event"))


def _set_qos(path, qos_of: dict) -> None:
    meta = yaml.safe_load((path / "metadata.yaml").read_text())
    for entry in meta["rosbag2_bagfile_information"]["topics_with_message_count"]:
        topic = entry["topic_metadata"]
        if topic["name"] in qos_of:
            profiles = [dict(p, reliability=qos_of[topic["name"]]) for p in _profiles(topic)]
            text = yaml.safe_dump(profiles)
            topic["offered_qos_profiles"] = (
                text if isinstance(topic["offered_qos_profiles"], str) else profiles
            )
    (path / "metadata.yaml").write_text(yaml.safe_dump(meta))


def _profiles(topic: dict) -> list:
    given = topic["offered_qos_profiles"]
    return yaml.safe_load(given) if isinstance(given, str) else given


def rows(log):
    return [tuple(row) for row in log[COLUMNS].itertuples(index=False)]


GOALS = [
    (at(1), "navigate_to_pose", "start", "r1"),
    (at(5), "navigate_to_pose", "complete", "r1"),
    (at(5.5), "navigate_to_pose", "start", "r1"),
    (at(8), "navigate_to_pose", "aborted", "r1"),
    (at(9), "navigate_to_pose", "start", "r1"),
    (at(10), "navigate_to_pose", "cancelled", "r1"),
]


def one_after_another(*spans: tuple[str, float, float]) -> list[tuple]:
    """The events of r1's activities (name, start, end), each ending when the next starts."""
    return [
        event
        for name, start, end in spans
        for event in ((at(start), name, "start", "r1"), (at(end), name, "complete", "r1"))
    ]


# the last value lasts until the end of the recording (10 s)
MODES = one_after_another(("idle", 0, 1), ("navigating", 1, 5), ("idle", 5, 10))
STORAGES_AND_DISTROS = [(s, d) for s in ("sqlite3", "mcap") for d in ("humble", "iron", "jazzy")]


def quiet_prepare(bag, **options):
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always", PreparationWarning)
        log = prepare(bag, perspectives=[], rate=0, **options)
    return log, [str(w.message) for w in caught if w.category is PreparationWarning]


def by_time(expected):
    return sorted(expected, key=lambda row: row[0])


@pytest.mark.parametrize(("storage", "distro"), STORAGES_AND_DISTROS)
def test_action_goals_become_activities_with_their_outcome(tmp_path, storage, distro):
    bag = Nav2Bag().write(tmp_path / "nav", storage, distro)
    log, warned = quiet_prepare(bag, tags="/none", actions="/*/_action/status")
    assert rows(log) == GOALS
    assert log["source_topic"].tolist() == [STATUS] * 6
    # the status messages (numbered from 0) where each event was seen
    assert log["source_index"].tolist() == [0, 2, 3, 4, 5, 7]
    assert log["execution_id"].nunique() == 3
    assert not warned


@pytest.mark.parametrize(("storage", "distro"), STORAGES_AND_DISTROS)
def test_a_mode_topic_becomes_activities_that_end_when_the_next_begins(tmp_path, storage, distro):
    bag = Nav2Bag().write(tmp_path / "nav", storage, distro)
    log, _ = quiet_prepare(bag, tags="/none", states=["/*/mode"])
    assert rows(log) == MODES


@pytest.mark.parametrize(("storage", "distro"), STORAGES_AND_DISTROS)
def test_tags_without_lifecycle_are_events_or_implicit_activities(tmp_path, storage, distro):
    bag = Nav2Bag().write(tmp_path / "nav", storage, distro)
    fields = TagFields.parse(["activity=action", "lifecycle=", "robot="])
    log, warned = quiet_prepare(bag, tags="/r1/events", tag_fields=fields)
    assert rows(log) == [(at(0.5), "boot", "complete", "r1"), (at(4), "check", "complete", "r1")]
    assert any("--lifecycle implicit" in w for w in warned)
    log, warned = quiet_prepare(bag, tags="/r1/events", tag_fields=fields, lifecycle="implicit")
    assert rows(log) == [
        (at(0.5), "boot", "start", "r1"),
        (at(4), "boot", "complete", "r1"),
        (at(4), "check", "start", "r1"),
        (at(10), "check", "complete", "r1"),
    ]
    assert not any("--lifecycle implicit" in w for w in warned), warned


def test_auto_finds_actions_and_modes_and_says_so(tmp_path):
    bag = Nav2Bag().write(tmp_path / "nav", "mcap", "humble")
    said = []
    log, _ = quiet_prepare(bag, auto=True, report=said.append)
    assert rows(log) == by_time(GOALS + MODES)
    # Humble has no service events (service_msgs): the one topic that cannot be looked into
    assert said == [
        "nav: activities from --actions /*/_action/status, --state-topic /r1/mode:data (1 "
        "topic(s) not looked into, their types having no definition: /r1/get_plan/_service_event "
        "(test_msgs/srv/BasicTypes_Event); give them with --msg)"
    ]


@pytest.mark.parametrize(("storage", "distro"), STORAGES_AND_DISTROS)
def test_a_qos_mismatch_in_the_metadata_is_read_around(tmp_path, storage, distro):
    best_effort = 2 if distro in ("humble", "iron") else "best_effort"  # as each one writes it
    bag = Nav2Bag().write(tmp_path / "nav", storage, distro, qos_of={"/r1/mode": best_effort})
    with Reader(bag) as reader:  # rosbags alone sees no message on it
        mode = [c for c in reader.connections if c.topic == "/r1/mode"]
        assert list(reader.messages(connections=mode)) == []
    log, warned = quiet_prepare(bag, tags="/none", states=["/*/mode"])
    assert rows(log) == MODES
    assert any("metadata.yaml describes /r1/mode with other QoS" in w for w in warned)


@pytest.mark.parametrize(("storage", "distro"), STORAGES_AND_DISTROS)
def test_a_wrong_stored_definition_is_refused_naming_the_topic(tmp_path, storage, distro):
    bag = Nav2Bag().write(
        tmp_path / "nav", storage, distro, definitions={"rcl_interfaces/msg/Log": "uint8 level\n"}
    )
    # only the topics asked for are decoded: the goals are read, /rosout is not
    log, _ = quiet_prepare(bag, tags="/none", actions="/*/_action/status")
    assert rows(log) == GOALS
    with pytest.raises(InputError) as error:
        prepare(bag, tags="/none", states=["/rosout:level"], perspectives=[])
    assert str(error.value).startswith(
        f"{bag}: a message on /rosout cannot be decoded as rcl_interfaces/msg/Log (CDR message "
        "size mismatch"
    )
    # the right definition, given by the user, wins over the stored one
    given = tmp_path / "rcl_interfaces" / "msg" / "Log.msg"
    given.parent.mkdir(parents=True)
    given.write_text(
        "builtin_interfaces/Time stamp\nuint8 level\nstring name\nstring msg\nstring file\n"
        "string function\nuint32 line\n"
    )
    log, _ = quiet_prepare(bag, tags="/none", states=["/rosout:name"], msg_files=[given])
    # /rosout has no namespace: its robot is the bag's only namespace
    assert rows(log) == [(at(3), "nav", "start", "r1"), (at(10), "nav", "complete", "r1")]


@pytest.mark.parametrize("storage", ["sqlite3", "mcap"])
def test_a_service_event_topic_is_read_with_the_service_definition_the_bag_stores(
    tmp_path, storage
):
    """rosbag2 stores a service event's definition as the service's .srv text."""
    bag = Nav2Bag().write(tmp_path / "nav", storage)
    log, _ = quiet_prepare(
        bag, tags="/none", states=["/r1/get_plan/_service_event:info.event_type"]
    )
    # 0 (request sent) from 2 s, then 3 (response received) until the end of the recording
    assert rows(log) == one_after_another(("0", 2, 2.5), ("3", 2.5, 10))
    tables = read_bag(bag, ["/r1/get_plan/_service_event"])
    assert tables["/r1/get_plan/_service_event"]["info.sequence_number"].tolist() == [7, 7]


@pytest.mark.parametrize("storage", ["sqlite3", "mcap"])
def test_a_service_event_without_a_definition_names_the_srv_file(tmp_path, storage):
    bag = Nav2Bag().write(tmp_path / "nav", storage, service_def="")
    with pytest.raises(InputError) as error:
        prepare(
            bag, tags="/none", states=["/r1/get_plan/_service_event:info.event_type"],
            perspectives=[],
        )  # fmt: skip
    assert "the message type test_msgs/srv/BasicTypes_Event is defined neither" in str(error.value)
    assert "--msg test_msgs/srv/BasicTypes.srv" in str(error.value)
    srv = tmp_path / "test_msgs" / "srv" / "BasicTypes.srv"
    srv.parent.mkdir(parents=True)
    srv.write_text(
        "bool bool_value\nstring string_value\n---\nbool bool_value\nstring string_value\n"
    )
    log, _ = quiet_prepare(
        bag, tags="/none", states=["/r1/get_plan/_service_event:info.event_type"],
        msg_files=[srv],
    )  # fmt: skip
    assert rows(log) == one_after_another(("0", 2, 2.5), ("3", 2.5, 10))


def test_a_defaulted_robot_and_an_empty_activity_are_warnings(tmp_path):
    b = Nav2Bag()
    b.add(6, "/events", EVENT_TYPE, b.t[EVENT_TYPE](action="dock"))
    b.add(7, "/events", EVENT_TYPE, b.t[EVENT_TYPE](action=""))
    bag = b.write(tmp_path / "nav")
    fields = TagFields.parse(["activity=action", "lifecycle=", "robot="])
    log, warned = quiet_prepare(bag, tags="/events", tag_fields=fields, lifecycle="events")
    assert rows(log) == [(at(6), "dock", "complete", "r1")]  # the bag's only namespace
    assert any(
        "/events (my_msgs/msg/Event) has no namespace, so its activities are of robot 'r1' "
        "(the only namespace of its topics); name the robot with --robot NAME." in w
        for w in warned
    )
    assert any("1 tag(s) on /events have an empty activity" in w for w in warned)


BT_CHANGE = "nav2_msgs/msg/BehaviorTreeStatusChange"
BT_LOG = "nav2_msgs/msg/BehaviorTreeLog"


def test_behaviour_tree_transitions_become_activities(tmp_path):
    b = Nav2Bag()
    b.store.register(
        {
            **get_types_from_msg(
                "builtin_interfaces/Time timestamp\nstring node_name\nstring previous_status\n"
                "string current_status\n",
                BT_CHANGE,
            ),
            **get_types_from_msg(
                "builtin_interfaces/Time timestamp\nBehaviorTreeStatusChange[] event_log\n", BT_LOG
            ),
        }
    )
    change = b.t[BT_CHANGE]
    for t, changes in (
        (1, [("ComputePath", "IDLE", "RUNNING"), ("Spin", "IDLE", "RUNNING")]),
        (2, [("ComputePath", "RUNNING", "SUCCESS"), ("Spin", "RUNNING", "IDLE")]),
        (3, [("ComputePath", "SUCCESS", "IDLE"), ("GoalReached", "IDLE", "FAILURE")]),
    ):
        log = [change(timestamp=b.time(t), node_name=n, previous_status=p, current_status=c)
               for n, p, c in changes]  # fmt: skip
        b.add(t, "/r1/behavior_tree_log", BT_LOG, b.t[BT_LOG](timestamp=b.time(t), event_log=log))
    bag = b.write(tmp_path / "nav")
    log, _ = quiet_prepare(bag, tags="/none", bt_logs="/*/behavior_tree_log")
    assert rows(log) == [
        (at(1), "ComputePath", "start", "r1"),
        (at(1), "Spin", "start", "r1"),
        (at(2), "ComputePath", "complete", "r1"),
        (at(2), "Spin", "cancelled", "r1"),  # halted
        (at(3), "GoalReached", "start", "r1"),  # failed at once: an instant activity
        (at(3), "GoalReached", "aborted", "r1"),
    ]
    said = []
    quiet_prepare(bag, tags="/none", auto=True, report=said.append)
    assert "--bt-log /r1/behavior_tree_log" in said[0]


FEEDBACK = "/r1/navigate_to_pose/_action/feedback"
FEEDBACK_TYPE = "demo_nav_msgs/action/NavigateToPose_FeedbackMessage"
#: the action's definition as demo_nav_msgs ships it (the parts that matter here)
NAVIGATE_ACTION = (
    "geometry_msgs/PoseStamped pose\nstring behavior_tree\n---\nstd_msgs/Empty result\n---\n"
    "float32 distance_remaining\nint16 number_of_recoveries\n"
)
SEPARATOR = "=" * 80 + "\n"
#: the feedback message's full text, as a recorder that resolves action types stores it
FEEDBACK_DEF = (
    "unique_identifier_msgs/UUID goal_id\ndemo_nav_msgs/action/NavigateToPose_Feedback feedback\n"
    f"{SEPARATOR}MSG: demo_nav_msgs/action/NavigateToPose_Feedback\n"
    "float32 distance_remaining\nint16 number_of_recoveries\n"
    f"{SEPARATOR}MSG: unique_identifier_msgs/UUID\nuint8[16] uuid\n"
)


def with_feedback(stored: str) -> Nav2Bag:
    """The navigation with feedback on goals 1 and 2, its definition stored as ``stored``."""
    b = Nav2Bag()
    b.store.register(get_types_from_msg(FEEDBACK_DEF, FEEDBACK_TYPE))
    t = b.t
    for seconds, goal, left in ((2, 1, 8.0), (3, 1, 6.0), (4, 1, 2.5), (6, 2, 7.0), (7, 2, 3.0)):
        uuid = t["unique_identifier_msgs/msg/UUID"](uuid=np.full(16, goal, np.uint8))
        feedback = t["demo_nav_msgs/action/NavigateToPose_Feedback"](
            distance_remaining=left, number_of_recoveries=0
        )
        b.add(seconds, FEEDBACK, FEEDBACK_TYPE, t[FEEDBACK_TYPE](goal_id=uuid, feedback=feedback))
    b.stored = {FEEDBACK_TYPE: stored}
    return b


LEFT = "left=/*/navigate_to_pose/_action/feedback:feedback.distance_remaining"


@pytest.mark.parametrize("storage", ["sqlite3", "mcap"])
def test_action_feedback_is_a_perspective_of_the_actions_robot(tmp_path, storage):
    b = with_feedback(FEEDBACK_DEF)
    bag = b.write(tmp_path / "nav", storage, "jazzy", definitions=b.stored)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always", PreparationWarning)
        log = prepare(bag, tags="/none", actions="/*/_action/status", rate=0, perspectives=[LEFT])
    assert not [str(w.message) for w in caught if "left" in str(w.message)]
    assert rows(log) == GOALS
    # each event takes the first sample at or after it, of robot r1 (the action's namespace);
    # after the last sample (7 s), that last one
    assert log["left"].tolist() == [8.0, 7.0, 7.0, 3.0, 3.0, 3.0]


def test_an_action_file_defines_the_feedback_a_bag_leaves_undefined(tmp_path):
    """rosbag2 stores no definition for action types (its search knows msg/ and srv/ only)."""
    b = with_feedback("")
    bag = b.write(tmp_path / "nav", "mcap", "jazzy", definitions=b.stored)
    with pytest.raises(InputError) as error:
        prepare(bag, tags="/none", actions="/*/_action/status", rate=0, perspectives=[LEFT])
    assert "--msg demo_nav_msgs/action/NavigateToPose.action" in str(error.value)
    action = tmp_path / "demo_nav_msgs" / "action" / "NavigateToPose.action"
    action.parent.mkdir(parents=True)
    action.write_text(NAVIGATE_ACTION)
    log = prepare(
        bag, tags="/none", actions="/*/_action/status", rate=0, perspectives=[LEFT],
        msg_files=[action],
    )  # fmt: skip
    assert log["left"].tolist() == [8.0, 7.0, 7.0, 3.0, 3.0, 3.0]


DOCK_TYPE = "my_msgs/msg/DockState"


def test_an_enum_state_topic_names_its_activities_after_the_constants(tmp_path):
    b = Nav2Bag()
    enum = "uint8 IDLE=0\nuint8 DOCKING=1\nuint8 CHARGING=2\nuint8 mode\n"
    b.store.register(get_types_from_msg(enum, DOCK_TYPE))
    for seconds, mode in ((0, 0), (2, 1), (4, 1), (6, 2)):
        b.add(seconds, "/r1/dock_state", DOCK_TYPE, b.t[DOCK_TYPE](mode=mode))
    bag = b.write(tmp_path / "nav", "sqlite3", "iron")
    log, _ = quiet_prepare(bag, tags="/none", states=["/r1/dock_state:mode"])
    assert rows(log) == one_after_another(("IDLE", 0, 2), ("DOCKING", 2, 6), ("CHARGING", 6, 10))
    assert log["source_index"].tolist() == [0, 1, 1, 3, 3, 3]


@pytest.mark.parametrize("storage", ["sqlite3", "mcap"])
def test_tags_with_only_starts_end_at_the_robots_next_tag(tmp_path, storage):
    from robotale.fame_runtime.tags import TAG_TYPE, register_tag_type

    b = Nav2Bag()
    register_tag_type(b.store)
    for seconds, activity, lifecycle in (
        (0.5, "boot", "start"),
        (4, "check", "start"),
        (6, "check", "complete"),  # one the robot does end: kept as it is
        (7, "dock", "start"),
    ):
        tag = b.t[TAG_TYPE](
            stamp=b.time(seconds), robot="r1", activity=activity, lifecycle=lifecycle,
            msg_id="", msg_role="", payload="",
        )  # fmt: skip
        b.add(seconds, "/r1/tag", TAG_TYPE, tag)
    bag = b.write(tmp_path / "nav", storage, "humble")
    log, _ = quiet_prepare(bag, lifecycle="implicit")
    assert rows(log) == [
        (at(0.5), "boot", "start", "r1"),
        (at(4), "boot", "complete", "r1"),  # the next tag ends it
        (at(4), "check", "start", "r1"),
        (at(6), "check", "complete", "r1"),
        (at(7), "dock", "start", "r1"),
        (at(10), "dock", "complete", "r1"),  # the end of the recording
    ]
    # an added complete comes from the tag that started the activity
    assert log["source_index"].tolist() == [0, 0, 1, 2, 3, 3]
    explicit, _ = quiet_prepare(bag)  # as recorded: starts without completes
    assert rows(explicit) == [row for row in rows(log) if row[1:3] != ("boot", "complete")][:-1]
