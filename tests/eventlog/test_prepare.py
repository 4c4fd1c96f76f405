"""Bags written here with known values prepare to exactly the rows computed by hand."""

from __future__ import annotations

import math
import warnings

import pandas as pd
import pytest
from bagbuilder import agri_like, at
from rosbags.rosbag2 import Writer

from robotale.errors import InputError
from robotale.eventlog import schema
from robotale.eventlog.enrich import PreparationWarning
from robotale.eventlog.prepare import TagFields, find_runs, is_recording, prepare, robot_type
from robotale.fame_runtime.tags import TAG_TYPE

COLUMNS = [
    schema.CASE,
    schema.TIMESTAMP,
    schema.ACTIVITY,
    schema.LIFECYCLE,
    schema.STATE,
    schema.ROBOT,
    schema.ROBOT_TYPE,
    schema.MSG_ID,
    schema.MSG_ROLE,
    schema.X,
    schema.Y,
    schema.Z,
    schema.BATTERY,
    schema.EVENT_ID,
]


def rows(log: pd.DataFrame, columns=COLUMNS) -> list[tuple]:
    """The log's rows with every kind of missing value as None."""
    return [
        tuple(None if _missing(v) else v for v in row)
        for row in log[columns].itertuples(index=False)
    ]


def _missing(value) -> bool:
    return value is None or value is pd.NA or (isinstance(value, float) and math.isnan(value))


def expected_rows(case: str, x0: float = 0.0, drone_type: str = "Drone") -> list[tuple]:
    """By hand: each event takes the first sample at or after it (the last one after the end)."""
    d, t1 = ("drone", drone_type), ("tractor_1", "Tractor")
    start, complete, none, inprogress = "start", "complete", "none", "inprogress"
    table = [
        # time, activity, lifecycle, state, robot, msg, x, y, z, battery
        (0.5, "take_off", start, none, d, None, x0 + 1, 2, 1.5, 98),
        (1.5, "take_off", none, inprogress, d, None, x0 + 2, 4, 1.5, 98),
        (2.5, "take_off", complete, none, d, None, x0 + 3, 6, 1.5, 96),
        (2.5, "explore", start, none, d, None, x0 + 3, 6, 1.5, 96),
        (3.5, "explore", none, inprogress, d, None, x0 + 4, 8, 1.5, 96),
        (4.5, "explore", none, inprogress, d, None, x0 + 5, 10, 1.5, 94),
        (5.2, "explore", complete, none, d, None, x0 + 6, 12, 1.5, 94),
        (5.2, "weed_position!", start, none, d, "send", x0 + 6, 12, 1.5, 94),
        (5.2, "weed_position!", complete, none, d, "send", x0 + 6, 12, 1.5, 94),
        (5.3, "weed_position?", start, none, t1, "receive", x0 + 15.5, 0, 0, 70),
        (5.3, "weed_position?", complete, none, t1, "receive", x0 + 15.5, 0, 0, 70),
        (5.4, "move", start, none, t1, None, x0 + 15.5, 0, 0, 70),
        (6.4, "move", none, inprogress, t1, None, x0 + 16.5, 0, 0, 70),
        (7.4, "move", complete, none, t1, None, x0 + 17.5, 0, 0, 70),
        (9.5, "land", start, none, d, None, x0 + 10, 20, 1.5, 90),
        # after the last samples: the recording stopped first, the last ones count
        (10.5, "land", complete, none, d, None, x0 + 10, 20, 1.5, 90),
    ]
    return [
        (case, at(t), activity, lifecycle, state, *robot, "m1" if role else None, role,
         float(x), float(y), float(z), float(battery), f"{case}:{i}")
        for i, (t, activity, lifecycle, state, robot, role, x, y, z, battery) in enumerate(table)
    ]  # fmt: skip


@pytest.mark.parametrize("storage", ["sqlite3", "mcap"])
def test_a_bag_prepares_to_exactly_the_expected_rows(tmp_path, bag_builder, storage):
    bag = agri_like(bag_builder).write(tmp_path / "run_0001", storage=storage)
    log = prepare(bag, rate=1.0)
    assert rows(log) == expected_rows("run_0001")
    assert log[schema.TIMESTAMP].dt.tz is not None
    payloads = log.loc[log[schema.MSG_ID].notna(), schema.MSG_PAYLOAD]
    assert payloads.tolist() == ['{"x": 6}'] * 4


def test_every_run_of_a_batch_is_one_case_and_keeps_its_own_samples(tmp_path, bag_builder):
    agri_like(bag_builder).write(
        tmp_path / "run_0001", manifest={"seed": 1, "robots": {"drone": "Quadcopter"}}
    )
    agri_like(bag_builder, x0=100.0).write(tmp_path / "run_0002")
    (tmp_path / "summary.json").write_text("{}")
    log = prepare(tmp_path)
    assert rows(log) == expected_rows("run_0001", drone_type="Quadcopter") + expected_rows(
        "run_0002", x0=100.0
    )


def test_rate_sets_how_many_inprogress_rows(tmp_path, bag_builder):
    bag = agri_like(bag_builder).write(tmp_path / "run")
    progress = lambda log: log.loc[log[schema.STATE] == "inprogress", schema.TIMESTAMP]  # noqa: E731
    # take_off 0.5-2.5, explore 2.5-5.2, move 5.4-7.4, land 9.5-10.5, every 0.5 s strictly inside
    halves = [1.0, 1.5, 2.0, 3.0, 3.5, 4.0, 4.5, 5.0, 5.9, 6.4, 6.9, 10.0]
    assert sorted(progress(prepare(bag, rate=2.0))) == [at(t) for t in halves]
    assert progress(prepare(bag, rate=0)).empty


def test_a_complete_without_start_is_kept_with_a_warning(tmp_path, bag_builder):
    b = agri_like(bag_builder)
    b.tag(8.0, "tractor_1", "cut_grass", "complete").tag(8.5, "tractor_1", "cut_grass", "complete")
    bag = b.write(tmp_path / "run")
    with pytest.warns(PreparationWarning, match=r"^2 complete event\(s\) have no start"):
        log = prepare(bag)
    kept = log[log[schema.ACTIVITY] == "cut_grass"]
    assert kept[schema.LIFECYCLE].tolist() == ["complete", "complete"]
    assert kept[schema.X].tolist() == [18.0, 18.5]


def test_perspectives_are_chosen_and_any_topic_field_can_be_one(tmp_path, bag_builder):
    b = agri_like(bag_builder)
    definition = "std_msgs/Header header\nfloat32 range\n"
    for t in range(11):
        b.custom(
            t, "/drone/range", "my_sensors/msg/Range", definition,
            header=b._header(t), range=0.25 * t,
        )  # fmt: skip
    bag = b.write(tmp_path / "run")
    with pytest.warns(PreparationWarning, match=r"1 robot\(s\) have tags but no range samples"):
        log = prepare(bag, perspectives=["battery", "range=/*/range:range"])
    assert schema.X not in log
    drone = log[log[schema.ROBOT] == "drone"]
    # the upper-closest range sample of each drone event, as for odometry: x + 0 is t rounded up
    assert drone["range"].tolist() == [0.25 * x for x in [1, 2, 3, 3, 4, 5, 6, 6, 6, 10, 10]]
    assert log.loc[log[schema.ROBOT] == "tractor_1", "range"].isna().all()


def test_a_bag_from_a_real_robot_with_its_own_tag_message(tmp_path, bag_builder):
    """No robot field, other field names, un-namespaced odometry: a one-robot ROS 2 bag."""
    definition = "builtin_interfaces/Time stamp\nstring action\nstring status\n"
    b = bag_builder()
    for t in range(6):
        b.odom(t, None, t, 0, 0, topic="/odom")
    for t, action, status in ((0.5, "dock", "START"), (2.5, "dock", "Complete"), (3, "beep", "")):
        b.custom(t, "/turtle/events", "turtle_msgs/msg/Event", definition,
                 stamp=b._time(t), action=action, status=status)  # fmt: skip
    bag = b.write(tmp_path / "tb3")
    log = prepare(
        bag,
        tags="/*/events",
        tag_fields=TagFields.parse(["activity=action", "lifecycle=status"]),
        perspectives=["odom"],
        rate=1.0,
    )
    assert rows(log, [schema.CASE, schema.ACTIVITY, schema.LIFECYCLE, schema.ROBOT, schema.X]) == [
        ("tb3", "dock", "start", "turtle", 1.0),
        ("tb3", "dock", "none", "turtle", 2.0),
        ("tb3", "dock", "complete", "turtle", 3.0),
        ("tb3", "beep", "none", "turtle", 3.0),
    ]
    assert set(log[schema.ROBOT_TYPE]) == {"Turtle"}


def test_bag_time_replaces_message_stamps(tmp_path, bag_builder):
    b = bag_builder()
    b.odom(0, "drone", 1, 0, 0).odom(5, "drone", 2, 0, 0)
    b.tag(3, "drone", "hover", "none", recorded=4.0)
    bag = b.write(tmp_path / "run")
    assert prepare(bag, perspectives=["odom"])[schema.TIMESTAMP].tolist() == [at(3)]
    log = prepare(bag, perspectives=["odom"], bag_time=True)
    assert log[schema.TIMESTAMP].tolist() == [at(4)]
    assert log[schema.X].tolist() == [2.0]


def test_what_counts_as_a_recording(tmp_path, bag_builder):
    bag = agri_like(bag_builder).write(tmp_path / "runs" / "run_0001")
    (tmp_path / "log.csv").write_text("case,time,activity\n")
    assert is_recording(bag) and is_recording(tmp_path / "runs")
    assert not is_recording(tmp_path / "log.csv")
    assert not is_recording(tmp_path) and not is_recording(tmp_path / "missing")


def test_robot_type_from_the_name():
    assert [robot_type(n) for n in ("tractor_1", "drone", "rex", "Tractor2", "uav-12")] == [
        "Tractor",
        "Drone",
        "Rex",
        "Tractor",
        "Uav",
    ]


# ----------------------------------------------------------------------------- bad input


def test_not_a_bag(tmp_path):
    (tmp_path / "notes").mkdir()
    with pytest.raises(InputError, match=r"is not a rosbag2 directory \(it has no metadata.yaml\)"):
        prepare(tmp_path)
    with pytest.raises(InputError, match="does not exist"):
        prepare(tmp_path / "missing")
    (tmp_path / "log.csv").write_text("a,b\n")
    with pytest.raises(InputError, match=r"log.csv is not a rosbag2 directory"):
        prepare(tmp_path / "log.csv")


def test_an_interrupted_recording_in_a_batch_is_named(tmp_path, bag_builder):
    agri_like(bag_builder).write(tmp_path / "run_0001")
    broken = tmp_path / "run_0002"
    broken.mkdir()
    (broken / "run_0002_0.db3").write_bytes(b"")
    with pytest.raises(
        InputError, match=r"run_0002 holds run_0002_0.db3 but no metadata.yaml .*`ros2 bag reindex "
    ):
        find_runs(tmp_path)


def test_a_bag_with_no_tag_topic_lists_its_topics(tmp_path, bag_builder):
    bag = bag_builder().odom(0, "drone", 0, 0, 0).battery(0, "drone", 1).write(tmp_path / "run")
    with pytest.raises(InputError) as error:
        prepare(bag)
    assert str(error.value) == (
        f"{bag} has no tag topic matching '/*/tag'; its topics are /drone/battery, /drone/odom "
        "(name the tag topics with --tags)."
    )


def test_tag_topics_without_messages_are_an_error(tmp_path, bag_builder):
    with Writer(tmp_path / "quiet", version=9) as writer:
        writer.add_connection("/drone/tag", TAG_TYPE, typestore=bag_builder().typestore)
    with pytest.raises(InputError) as error:
        prepare(tmp_path / "quiet")
    assert str(error.value) == (
        f"{tmp_path / 'quiet'} has no tags: its topics matching '/*/tag' (/drone/tag) hold no "
        "message."
    )


def test_tags_without_the_activity_field_say_which_fields_they_have(tmp_path, bag_builder):
    b = bag_builder().tag(0, "drone", "take_off", "start")
    bag = b.write(tmp_path / "run")
    with pytest.raises(InputError, match=r"no field 'action' for the activity; name it with "):
        prepare(bag, tag_fields=TagFields(activity="action"))


def test_an_unknown_lifecycle_is_named(tmp_path, bag_builder):
    bag = bag_builder().tag(1, "drone", "take_off", "begin").write(tmp_path / "run")
    with pytest.raises(
        InputError, match=r"has lifecycle 'begin'; expected start, complete or none"
    ):
        prepare(bag)


def test_an_un_namespaced_topic_in_a_multi_robot_bag_is_refused(tmp_path, bag_builder):
    b = agri_like(bag_builder).odom(1, None, 0, 0, 0, topic="/odom")
    with pytest.raises(InputError, match=r"/odom has no namespace, so it cannot be told which"):
        prepare(b.write(tmp_path / "run"))


def test_bad_tag_field_and_perspective_specs():
    with pytest.raises(InputError, match="is not KEY=FIELD"):
        TagFields.parse(["colour=red"])
    with pytest.raises(InputError, match="Unknown perspective 'lidar'"):
        prepare("unused", perspectives=["lidar"])


def test_no_warning_on_a_clean_bag(tmp_path, bag_builder):
    bag = agri_like(bag_builder).write(tmp_path / "run")
    with warnings.catch_warnings():
        warnings.simplefilter("error", PreparationWarning)
        prepare(bag)
