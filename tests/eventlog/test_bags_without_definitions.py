"""Bags as robots record them without definitions: Nav2's behaviour-tree log, old-style type
names, topics without a namespace, messages whose activity is empty.

Each bag is written with rosbags' writer (each storage; Humble's and Jazzy's layout) with
definitions written here, then stored without any; counts are checked with rosbags alone.
"""

from __future__ import annotations

import warnings

import pytest
from bagbuilder import at, nanos
from rosbags.rosbag2 import Reader, StoragePlugin, Writer
from rosbags.typesys import Stores, get_types_from_msg, get_typestore

from robotale.errors import InputError
from robotale.eventlog import schema
from robotale.eventlog.enrich import PreparationWarning
from robotale.eventlog.prepare import prepare
from robotale.sim import bagmeta

BT_LOG, BT_CHANGE = "nav2_msgs/msg/BehaviorTreeLog", "nav2_msgs/msg/BehaviorTreeStatusChange"
#: the fields of Nav2's status change, by distribution (Jazzy added the node's id)
CHANGE_FIELDS = {
    "humble": "builtin_interfaces/Time timestamp\nstring node_name\nstring previous_status\n"
    "string current_status\n",
    "jazzy": "builtin_interfaces/Time timestamp\nstring node_name\nuint16 uid\n"
    "string previous_status\nstring current_status\n",
}
#: (seconds, [(node, previous, current)]) as a Nav2 navigator publishes them
TRANSITIONS = [
    (1.0, [("NavigateRecovery", "IDLE", "RUNNING"), ("ComputePathToPose", "IDLE", "RUNNING")]),
    (1.5, [("ComputePathToPose", "RUNNING", "SUCCESS"), ("FollowPath", "IDLE", "RUNNING")]),
    (2.0, [("ComputePathToPose", "SUCCESS", "IDLE")]),  # a reset: no event
    (4.25, [("FollowPath", "RUNNING", "FAILURE"), ("Spin", "IDLE", "RUNNING")]),
    (6.0, [("Spin", "RUNNING", "SUCCESS"), ("ComputePathToPose", "IDLE", "RUNNING")]),
    (6.000000001, [("ComputePathToPose", "RUNNING", "SUCCESS")]),
    (9.0, [("NavigateRecovery", "RUNNING", "SUCCESS")]),
]
#: counted by hand from TRANSITIONS: (node, outcome, nanoseconds it lasted), in start order
ACTIVITIES = [
    ("NavigateRecovery", "complete", 8_000_000_000),
    ("ComputePathToPose", "complete", 500_000_000),
    ("FollowPath", "aborted", 2_750_000_000),
    ("Spin", "complete", 1_750_000_000),
    ("ComputePathToPose", "complete", 1),
]
STORAGES_AND_DISTROS = [(s, d) for s in ("sqlite3", "mcap") for d in ("humble", "jazzy")]


def nav2_bag(path, storage: str, distro: str, topic: str = "/behavior_tree_log"):
    """A behaviour-tree log with no definition stored (as a Humble sqlite3 bag has none)."""
    store = get_typestore(Stores.ROS2_HUMBLE)
    store.register(get_types_from_msg(CHANGE_FIELDS[distro], BT_CHANGE))
    store.register(
        get_types_from_msg(
            "builtin_interfaces/Time timestamp\nBehaviorTreeStatusChange[] event_log\n", BT_LOG
        )
    )
    t = store.types

    def time(seconds):
        n = nanos(seconds)
        return t["builtin_interfaces/msg/Time"](sec=n // 10**9, nanosec=n % 10**9)

    plugin = StoragePlugin.MCAP if storage == "mcap" else StoragePlugin.SQLITE3
    with Writer(path, version=bagmeta.writer_version(distro), storage_plugin=plugin) as writer:
        connection = writer.add_connection(topic, BT_LOG, msgdef="", rihs01="RIHS01_" + "0" * 64)
        for seconds, changes in TRANSITIONS:
            extra = {"uid": 3} if distro == "jazzy" else {}
            events = [
                t[BT_CHANGE](timestamp=time(seconds), node_name=node, previous_status=before,
                             current_status=after, **extra)
                for node, before, after in changes
            ]  # fmt: skip
            message = t[BT_LOG](timestamp=time(seconds), event_log=events)
            writer.write(connection, nanos(seconds), store.serialize_cdr(message, BT_LOG))
    bagmeta.for_distro(path, distro)
    return path


def counted_by_rosbags(bag) -> int:
    with Reader(bag) as reader:
        assert all(not c.msgdef.data.strip() for c in reader.connections)  # none stored
        return sum(1 for _ in reader.messages())


def durations(log) -> list[tuple[str, str, int]]:
    """(node, outcome, nanoseconds) of each activity, pairing each start with its end."""
    open_at: dict[str, list] = {}
    found = []
    for time, node, lifecycle in zip(
        log[schema.TIMESTAMP], log[schema.ACTIVITY], log[schema.LIFECYCLE], strict=True
    ):
        if lifecycle == "start":
            open_at.setdefault(node, []).append((len(found), time))
            found.append(None)
        else:
            position, began = open_at[node].pop(0)
            found[position] = (node, lifecycle, (time - began).value)
    return found


def quiet(bag, **options):
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always", PreparationWarning)
        log = prepare(bag, perspectives=[], rate=0, **options)
    return log, [str(w.message) for w in caught]


@pytest.mark.parametrize(("storage", "distro"), STORAGES_AND_DISTROS)
def test_a_nav2_behaviour_tree_log_without_definitions_prepares(tmp_path, storage, distro):
    bag = nav2_bag(tmp_path / "nav", storage, distro)
    assert counted_by_rosbags(bag) == len(TRANSITIONS)
    log, warned = quiet(bag, tags="/none", bt_logs="/behavior_tree_log", robot="tb3")
    assert durations(log) == ACTIVITIES
    assert set(log[schema.ROBOT]) == {"tb3"} and not warned
    said: list[str] = []
    auto, _ = quiet(bag, tags="/none", auto=True, report=said.append)
    assert said == ["nav: activities from --bt-log /behavior_tree_log"]
    assert durations(auto) == ACTIVITIES


def test_without_robot_a_topic_without_namespace_is_the_default_robot_with_a_warning(tmp_path):
    bag = nav2_bag(tmp_path / "nav", "sqlite3", "humble")
    log, warned = quiet(bag, tags="/none", bt_logs="/behavior_tree_log")
    assert set(log[schema.ROBOT]) == {"robot"}
    assert warned == [
        f"{bag}: /behavior_tree_log ({BT_LOG}) has no namespace, so its activities are of robot "
        "'robot' (the bag's topics have no namespace); name the robot with --robot NAME."
    ]


def test_a_bt_log_of_the_wrong_distribution_is_refused_naming_the_file(tmp_path):
    bag = nav2_bag(tmp_path / "nav", "sqlite3", "jazzy")
    with pytest.raises(InputError) as error:
        prepare(bag, tags="/none", bt_logs="/behavior_tree_log", perspectives=[], distro="humble")
    assert "--msg nav2_msgs/msg/BehaviorTreeLog.msg" in str(error.value)


OLD_TYPE, OLD_DEF = "test_msgs/BasicTypes", "bool bool_value\nstring string_value\n"


@pytest.mark.parametrize("storage", ["sqlite3", "mcap"])
def test_an_old_style_type_name_is_read_with_the_file_the_error_names(tmp_path, storage):
    """Some bags record ``pkg/Type``; its definition is ``pkg/msg/Type.msg``."""
    store = get_typestore(Stores.ROS2_HUMBLE)
    store.register(get_types_from_msg(OLD_DEF, "test_msgs/msg/BasicTypes"))
    kind = store.types["test_msgs/msg/BasicTypes"]
    bag = tmp_path / "old"
    plugin = StoragePlugin.MCAP if storage == "mcap" else StoragePlugin.SQLITE3
    with Writer(bag, version=bagmeta.writer_version("humble"), storage_plugin=plugin) as writer:
        connection = writer.add_connection(
            "/r2/events", OLD_TYPE, msgdef="", rihs01="RIHS01_" + "0" * 64
        )
        for seconds, text in ((1, "pick"), (2, ""), (3, "drop")):
            raw = store.serialize_cdr(kind(bool_value=True, string_value=text), kind.__msgtype__)
            writer.write(connection, nanos(seconds), raw)
    bagmeta.for_distro(bag, "humble")
    with Reader(bag) as reader:
        assert [c.msgtype for c in reader.connections] == [OLD_TYPE]
        assert reader.message_count == 3
    options = {"tags": "/r2/events", "lifecycle": "events"}
    fields = ["activity=string_value", "lifecycle=", "robot=", "msg_id=", "msg_role=", "payload="]
    from robotale.eventlog.prepare import TagFields  # why: only these tests name tag fields

    options["tag_fields"] = TagFields.parse(fields)
    with pytest.raises(InputError) as error:
        prepare(bag, perspectives=[], **options)
    assert "the message type test_msgs/msg/BasicTypes is defined neither" in str(error.value)
    assert "--msg test_msgs/msg/BasicTypes.msg" in str(error.value)
    given = tmp_path / "test_msgs" / "msg" / "BasicTypes.msg"
    given.parent.mkdir(parents=True)
    given.write_text(OLD_DEF)
    log, warned = quiet(bag, msg_files=[given], **options)
    assert list(zip(log[schema.TIMESTAMP], log[schema.ACTIVITY], strict=True)) == [
        (at(1), "pick"),
        (at(3), "drop"),
    ]
    assert any("1 tag(s) on /r2/events have an empty activity" in w for w in warned)


def test_tags_whose_activity_is_empty_are_counted_in_the_refusal(tmp_path):
    store = get_typestore(Stores.ROS2_HUMBLE)
    store.register(get_types_from_msg(OLD_DEF, "test_msgs/msg/BasicTypes"))
    kind = store.types["test_msgs/msg/BasicTypes"]
    bag = tmp_path / "blank"
    with Writer(bag, version=9) as writer:
        connection = writer.add_connection("/test_topic", kind.__msgtype__, typestore=store)
        for seconds in (1, 2):
            raw = store.serialize_cdr(kind(bool_value=False, string_value=""), kind.__msgtype__)
            writer.write(connection, nanos(seconds), raw)
    from robotale.eventlog.prepare import TagFields  # why: only these tests name tag fields

    fields = TagFields.parse(["activity=string_value", "lifecycle=", "robot="])
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", PreparationWarning)
        with pytest.raises(InputError) as error:
            prepare(bag, tags="/test_topic*", tag_fields=fields, perspectives=[])
    assert str(error.value) == (
        f"{bag} has no tags: its topics matching '/test_topic*' hold 2 message(s) whose "
        "activity field ('string_value') is empty; name the field that holds the activity with "
        "--tag-field activity=FIELD."
    )


def test_a_bag_without_metadata_suggests_reindexing_it(tmp_path):
    bag = nav2_bag(tmp_path / "nav", "sqlite3", "humble")
    (bag / "metadata.yaml").unlink()
    storage = next(bag.glob("*.db3")).name
    with pytest.raises(InputError) as error:
        prepare(bag, tags="/none", bt_logs="/behavior_tree_log", perspectives=[])
    assert str(error.value) == (
        f"{bag} holds {storage} but no metadata.yaml (was the recording interrupted?); "
        f"`ros2 bag reindex {bag}` writes it from the storage files, then prepare the folder "
        "again."
    )
