"""robotale's DDS samples are ROS 2's own CDR: rosbags, which reads what ROS 2 nodes write,
decodes them to the values sent and encodes those values to the very same bytes."""

import math

import pytest

pytest.importorskip("cyclonedds")

from rosbags.typesys import Stores, get_typestore

from robotale.fame_runtime.rostypes import dds_type_name, idl_type, to_sample

CASES = [
    ("std_msgs/msg/String", {"data": "weed at 3,4"}, {"data": "weed at 3,4"}),
    ("geometry_msgs/msg/Vector3", {"x": 3.0, "y": -4.5}, {"x": 3.0, "y": -4.5, "z": 0.0}),
    (
        "geometry_msgs/msg/Vector3Stamped",
        {"header": {"stamp": {"sec": 7, "nanosec": 5}, "frame_id": "field"}, "vector": {"x": 1.0}},
        {
            "header.stamp.sec": 7,
            "header.stamp.nanosec": 5,
            "header.frame_id": "field",
            "vector.x": 1.0,
        },
    ),
    (
        "sensor_msgs/msg/Range",
        {"radiation_type": 1, "field_of_view": 0.5, "range": 0.3, "max_range": 4.0},
        {"radiation_type": 1, "range": 0.3, "max_range": 4.0},
    ),
    (
        "geometry_msgs/msg/PoseWithCovariance",
        {"pose": {"orientation": {"w": 1.0}}, "covariance": [0.5] * 36},
        {"pose.orientation.w": 1.0, "covariance": [0.5] * 36},
    ),
    ("std_msgs/msg/Empty", {}, {}),
]


@pytest.mark.parametrize(("msgtype", "data", "expected"), CASES, ids=[c[0] for c in CASES])
def test_a_sample_is_the_cdr_a_ros_2_node_sends(msgtype, data, expected):
    store = get_typestore(Stores.ROS2_HUMBLE)
    wire = to_sample(msgtype, data, "/topic").serialize(use_version_2=False)  # plain CDR
    decoded = store.deserialize_cdr(wire, msgtype)
    for path, value in expected.items():
        found = decoded
        for name in path.split("."):
            found = getattr(found, name)
        if isinstance(value, float):
            assert math.isclose(found, value, rel_tol=1e-6), path
        elif isinstance(value, list):
            assert list(found) == value, path
        else:
            assert found == value, path
    assert bytes(store.serialize_cdr(decoded, msgtype)) == wire


def test_type_names_are_ros_2_idl_mangling():
    assert dds_type_name("std_msgs/msg/String") == "std_msgs::msg::dds_::String_"
    point = idl_type("geometry_msgs/msg/Point")
    assert point.__idl_typename__ == "geometry_msgs::msg::dds_::Point_"
