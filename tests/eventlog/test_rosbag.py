"""Reading rosbag2 directories into one table per topic."""

from __future__ import annotations

import shutil
import sqlite3

import pytest
import yaml
from bagbuilder import at, nanos

from robotale.errors import InputError
from robotale.eventlog.prepare import TagFields, prepare
from robotale.eventlog.rosbag import Bag, message_types, read_bag

EVENT_TYPE = "turtle_msgs/msg/Event"
EVENT_MSG = "builtin_interfaces/Time stamp\nstring action\nstring status\n"


@pytest.mark.parametrize("storage", ["sqlite3", "mcap"])
def test_every_scalar_field_of_every_topic_becomes_a_column(tmp_path, bag_builder, storage):
    b = bag_builder().odom(1.25, "drone", 1.5, -2.0, 3.25).odom(2, "drone", 4, 5, 6)
    b.battery(1, "drone", 0.98).tag(1.5, "drone", "explore", "start", "m1", "send", "{}")
    tables = read_bag(b.write(tmp_path / "bag", storage=storage))
    assert sorted(tables) == ["/drone/battery", "/drone/odom", "/drone/tag"]
    odom = tables["/drone/odom"]
    assert odom["time"].tolist() == [at(1.25), at(2)]
    assert odom["pose.pose.position.x"].tolist() == [1.5, 4.0]
    assert odom["pose.pose.position.z"].tolist() == [3.25, 6.0]
    assert odom["header.frame_id"].tolist() == ["odom", "odom"]
    assert odom["child_frame_id"].tolist() == ["base_link", "base_link"]
    assert not any("covariance" in c for c in odom.columns)  # arrays are left out
    # float32 readings come back as the decimals that were written
    assert tables["/drone/battery"]["percentage"].tolist() == [0.98]
    tag = tables["/drone/tag"].iloc[0]
    assert (tag["activity"], tag["lifecycle"], tag["msg_id"], tag["msg_role"]) == (
        "explore",
        "start",
        "m1",
        "send",
    )
    assert tag["stamp.sec"] * 10**9 + tag["stamp.nanosec"] == nanos(1.5)


def test_a_field_that_does_not_exist_is_named_with_the_fields_there_are(tmp_path, bag_builder):
    bag = bag_builder().battery(0, "drone", 1).write(tmp_path / "bag")
    with Bag(bag) as opened, pytest.raises(InputError, match=r"has no field 'charge_level'"):
        opened.tables({"/drone/battery": {"level": "charge_level"}})


def without_definitions(bag):
    """The bag as ROS 2 Humble records it: no message definitions inside."""
    database = next(bag.glob("*.db3"))
    with sqlite3.connect(database) as connection:
        connection.execute("DELETE FROM message_definitions")
    return bag


def humble_turtle_bag(tmp_path, bag_builder):
    b = bag_builder()
    for t, lifecycle in ((1, "start"), (2, "complete")):
        b.custom(t, "/turtle/events", EVENT_TYPE, EVENT_MSG, stamp=b._time(t), action="dock",
                 status=lifecycle)  # fmt: skip
    return without_definitions(b.write(tmp_path / "bag"))


def test_a_type_the_bag_does_not_define_is_named_with_how_to_register_it(tmp_path, bag_builder):
    bag = humble_turtle_bag(tmp_path, bag_builder)
    with pytest.raises(InputError) as error:
        read_bag(bag)
    assert str(error.value) == (
        f"{bag}: cannot decode /turtle/events: the message type {EVENT_TYPE} is defined neither "
        "in the bag nor among the Humble types robotale knows; give its definition with --msg "
        "turtle_msgs/msg/Event.msg (a file at that path, or a folder holding "
        "turtle_msgs/msg/Event.msg)."
    )


def test_a_missing_type_inside_a_registered_one_is_named(tmp_path, bag_builder):
    b = bag_builder()
    b.custom(0, "/arm/goal", "arm_msgs/msg/Target", "float64 x\n", x=0.5)
    b.custom(
        1, "/arm/plan", "arm_msgs/msg/Plan", "arm_msgs/Target goal\nstring name\n",
        goal=b.typestore.types["arm_msgs/msg/Target"](x=1.0), name="p",
    )  # fmt: skip
    bag = without_definitions(b.write(tmp_path / "bag"))
    given = tmp_path / "arm_msgs" / "msg" / "Plan.msg"
    given.parent.mkdir(parents=True)
    given.write_text("arm_msgs/Target goal\nstring name\n")
    with pytest.raises(InputError) as error:
        read_bag(bag, ["/arm/plan"], msg_files=[given])
    assert str(error.value).startswith(
        f"{bag}: cannot decode /arm/plan: the message type arm_msgs/msg/Target, which "
        "arm_msgs/msg/Plan contains, is defined neither in the bag nor among the Humble types "
        "robotale knows; give its definition with --msg "
        "arm_msgs/msg/Target.msg"
    )
    (given.parent / "Target.msg").write_text("float64 x\n")
    plan = read_bag(bag, ["/arm/plan"], msg_files=[given.parent])["/arm/plan"]
    assert (plan["goal.x"].tolist(), plan["name"].tolist()) == ([1.0], ["p"])


def test_types_registered_from_msg_files_decode_the_bag(tmp_path, bag_builder):
    bag = humble_turtle_bag(tmp_path, bag_builder)
    package = tmp_path / "src" / "turtle_msgs"
    (package / "msg").mkdir(parents=True)
    (package / "msg" / "Event.msg").write_text(EVENT_MSG)
    for given in (package / "msg" / "Event.msg", tmp_path / "src"):
        events = read_bag(bag, msg_files=[given])["/turtle/events"]
        assert events["status"].tolist() == ["start", "complete"]
    log = prepare(
        bag,
        tags="/turtle/events",
        tag_fields=TagFields.parse(["activity=action", "lifecycle=status"]),
        perspectives=[],
        rate=2.0,
        msg_files=[tmp_path / "src"],
    )
    assert log["lifecycle:transition"].tolist() == ["start", "none", "complete"]
    assert log["time:timestamp"].tolist() == [at(1), at(1.5), at(2)]


def test_a_definition_that_does_not_match_the_recording_is_refused(tmp_path, bag_builder):
    bag = humble_turtle_bag(tmp_path, bag_builder)
    wrong = tmp_path / "turtle_msgs" / "msg" / "Event.msg"
    wrong.parent.mkdir(parents=True)
    wrong.write_text("builtin_interfaces/Time stamp\nfloat64 a\nfloat64 b\nfloat64[] c\n")
    with pytest.raises(InputError, match=r"cannot be decoded as turtle_msgs/msg/Event \(.*\); the"):
        read_bag(bag, msg_files=[wrong])


def test_msg_files_must_say_their_package(tmp_path):
    loose = tmp_path / "Event.msg"
    loose.write_text(EVENT_MSG)
    with pytest.raises(InputError, match=r"Cannot tell the type name of .*Event.msg"):
        read_bag(tmp_path, msg_files=[loose])
    broken = tmp_path / "pkg" / "msg" / "Broken.msg"
    broken.parent.mkdir(parents=True)
    broken.write_text("int32[ x\n")
    with pytest.raises(InputError, match=r"Broken.msg cannot be parsed"):
        read_bag(tmp_path, msg_files=[broken])


def test_an_action_file_defines_its_parts_and_its_feedback_message(tmp_path):
    from rosbags.typesys.base import Nodetype

    action = tmp_path / "dock_msgs" / "action" / "Dock.action"
    action.parent.mkdir(parents=True)
    # Station is the package's own message, as rosidl reads a bare name in an .action file
    action.write_text("Station station\n---\nbool docked\n---\nfloat32 left\nStation[] near\n")
    typs = message_types([action])
    parts = ("Feedback", "FeedbackMessage", "Goal", "Result")
    assert sorted(typs) == [f"dock_msgs/action/Dock_{part}" for part in parts]
    assert typs["dock_msgs/action/Dock_Goal"][1] == [
        ("station", (Nodetype.NAME, "dock_msgs/msg/Station"))
    ]
    assert typs["dock_msgs/action/Dock_Feedback"][1][1] == (
        "near",
        (Nodetype.SEQUENCE, ((Nodetype.NAME, "dock_msgs/msg/Station"), 0)),
    )
    assert typs["dock_msgs/action/Dock_FeedbackMessage"][1] == [
        ("goal_id", (Nodetype.NAME, "unique_identifier_msgs/msg/UUID")),
        ("feedback", (Nodetype.NAME, "dock_msgs/action/Dock_Feedback")),
    ]
    action.write_text("bool go\n---\nbool done\n")
    with pytest.raises(InputError, match=r"Dock.action cannot be parsed: an action has a goal"):
        message_types([action])


def split_bag(tmp_path, first, second):
    """One rosbag2 directory whose two storage files are ``first`` then ``second``."""
    split = tmp_path / "split"
    split.mkdir()
    metadata = yaml.safe_load((first / "metadata.yaml").read_text())
    info = metadata["rosbag2_bagfile_information"]
    names = []
    for index, part in enumerate((first, second)):
        names.append(f"split_{index}.db3")
        shutil.copy(next(part.glob("*.db3")), split / names[-1])
    info["relative_file_paths"] = names
    info["files"] = []
    info["message_count"] *= 2
    for topic in info["topics_with_message_count"]:
        topic["message_count"] *= 2
    (split / "metadata.yaml").write_text(yaml.safe_dump(metadata))
    return split


def recording(tmp_path, bag_builder, name, start):
    b = bag_builder()
    for t in range(start, start + 3):
        b.odom(t, "drone", t, 0, 0).tag(t, "drone", "hover", "none")
    return b.write(tmp_path / name)


def test_a_split_bag_is_read_across_its_files(tmp_path, bag_builder):
    early, late = (recording(tmp_path, bag_builder, n, s) for n, s in (("a", 0), ("b", 10)))
    odom = read_bag(split_bag(tmp_path, early, late))["/drone/odom"]
    assert odom["pose.pose.position.x"].tolist() == [0, 1, 2, 10, 11, 12]


def test_timestamps_out_of_order_across_files_are_an_error(tmp_path, bag_builder):
    early, late = (recording(tmp_path, bag_builder, n, s) for n, s in (("a", 0), ("b", 10)))
    bag = split_bag(tmp_path, late, early)
    with pytest.raises(InputError) as error:
        prepare(bag)
    assert str(error.value).startswith(
        f"{bag}: timestamps are out of order across its files (split_0.db3, split_1.db3): "
    )
    assert not list(tmp_path.glob("**/*.csv"))


def test_unreadable_bags_are_named(tmp_path, bag_builder):
    bag = recording(tmp_path, bag_builder, "bag", 0)
    (bag / "metadata.yaml").write_text("rosbag2_bagfile_information: {{{\n")
    with pytest.raises(InputError, match=r"bag is not a readable rosbag2 directory: Could not"):
        prepare(bag)
    other = recording(tmp_path, bag_builder, "other", 0)
    next(other.glob("*.db3")).write_bytes(b"not a database" * 64)
    with pytest.raises(InputError, match=r"other is not a readable rosbag2 directory: .*database"):
        prepare(other)


@pytest.mark.parametrize("distro", ["humble", "jazzy", None])
def test_standard_types_come_from_the_distribution_when_the_bag_has_none(
    tmp_path, bag_builder, distro
):
    b = bag_builder().odom(1, "drone", 1.5, 2.5, 0).battery(1, "drone", 0.5)
    bag = without_definitions(b.write(tmp_path / "bag"))
    metadata = yaml.safe_load((bag / "metadata.yaml").read_text())
    info = metadata["rosbag2_bagfile_information"]
    info.pop("ros_distro") if distro is None else info.update(ros_distro=distro)
    (bag / "metadata.yaml").write_text(yaml.safe_dump(metadata))
    tables = read_bag(bag)
    assert tables["/drone/odom"]["pose.pose.position.y"].tolist() == [2.5]
    assert tables["/drone/battery"]["percentage"].tolist() == [0.5]
