"""C-QoS: the ROS 2 compatibility rules (thesis table 4.1 and the ROS 2 QoS documentation)
and the check of every publisher/subscriber pair of a collaboration."""

import pytest

from robotale.errors import ModelError
from robotale.fame_runtime.check import check
from robotale.fame_runtime.parser import parse
from robotale.fame_runtime.qos import QoS, incompatibilities, qos_from_policies


@pytest.mark.parametrize(
    ("publisher", "subscriber", "compatible"),
    [  # thesis table 4.1, row by row
        ("best_effort", "best_effort", True),
        ("best_effort", "reliable", False),
        ("reliable", "best_effort", True),
        ("reliable", "reliable", True),
    ],
)
def test_reliability_matrix_of_table_4_1(publisher, subscriber, compatible):
    reasons = incompatibilities(QoS(reliability=publisher), QoS(reliability=subscriber))
    assert (not reasons) is compatible
    if not compatible:
        assert reasons == [
            "reliability: the publisher offers best_effort, the subscriber requests reliable"
        ]


@pytest.mark.parametrize(
    ("offered", "requested", "compatible"),
    [
        (QoS(durability="volatile"), QoS(durability="transient_local"), False),
        (QoS(durability="transient_local"), QoS(durability="volatile"), True),
        (QoS(durability="transient_local"), QoS(durability="transient_local"), True),
        (QoS(deadline=5.0), QoS(deadline=2.0), False),
        (QoS(deadline=None), QoS(deadline=2.0), False),  # infinite offered, finite requested
        (QoS(deadline=2.0), QoS(deadline=None), True),
        (QoS(deadline=2.0), QoS(deadline=2.0), True),
        (QoS(liveliness="automatic"), QoS(liveliness="manual_by_topic"), False),
        (QoS(liveliness="manual_by_topic"), QoS(liveliness="automatic"), True),
        (QoS(lease_duration=10.0), QoS(lease_duration=3.0), False),
        (QoS(lease_duration=None), QoS(lease_duration=3.0), False),
        (QoS(lease_duration=3.0), QoS(lease_duration=10.0), True),
        # history, depth and lifespan never prevent a match
        (QoS(history="keep_all", depth=1, lifespan=1.0), QoS(depth=100, lifespan=None), True),
    ],
)
def test_other_policies_request_versus_offered(offered, requested, compatible):
    assert (not incompatibilities(offered, requested)) is compatible


def test_reasons_name_each_failing_policy():
    offered = QoS("best_effort", "volatile", deadline=5.0, lease_duration=None)
    requested = QoS(
        "reliable",
        "transient_local",
        deadline=2.0,
        liveliness="manual_by_topic",
        lease_duration=1.0,
    )
    assert incompatibilities(offered, requested) == [
        "reliability: the publisher offers best_effort, the subscriber requests reliable",
        "durability: the publisher offers volatile, the subscriber requests transient_local",
        "liveliness: the publisher offers automatic, the subscriber requests manual_by_topic",
        "deadline: the publisher offers 5 s, longer than the 2 s the subscriber requests",
        "lease_duration: the publisher offers infinite, longer than the 1 s the subscriber "
        "requests",
    ]


def test_policy_values_as_modelers_write_them():
    qos = qos_from_policies(
        {
            "Reliability": "Best Effort",
            "qos.durability": "Transient-Local",
            "deadline": "PT2S",
            "depth": "5",
            "lease_duration": "infinite",
        }
    )
    assert qos == QoS("best_effort", "transient_local", depth=5, deadline=2.0)
    with pytest.raises(
        ValueError, match="QoS reliability 'sometimes' is not one of reliable, best_effort"
    ):
        qos_from_policies({"reliability": "sometimes"})
    with pytest.raises(ValueError, match="'colour' is not a QoS policy"):
        qos_from_policies({"colour": "red"})


def test_bad_policy_in_a_model_names_the_element(tmp_path, models):
    text = (models / "qos.bpmn").read_text().replace('value="best_effort"', 'value="maybe"')
    path = tmp_path / "bad_qos.bpmn"
    path.write_text(text)
    with pytest.raises(
        ModelError,
        match=r"bad_qos.bpmn:15: signal event d_weed \(weed_position\): QoS reliability 'maybe'",
    ):
        parse(path)


def test_check_reports_every_pair_of_the_collaboration(models):
    report = check(parse(models / "qos.bpmn"))
    pairs = {
        (p.publisher.describe(), p.subscriber.describe()): list(p.reasons) for p in report.pairs
    }
    assert pairs == {
        ("Drone d_closest (closest_tractor)", "Tractor t_closest (closest_tractor)"): [],
        ("Tractor t_position (tractor_position)", "Drone d_position (tractor_position)"): [
            "durability: the publisher offers volatile, the subscriber requests transient_local",
            "deadline: the publisher offers 5 s, longer than the 2 s the subscriber requests",
        ],
        # figure 5.14a of the thesis
        ("Drone d_weed (weed_position)", "Tractor t_weed (weed_position)"): [
            "reliability: the publisher offers best_effort, the subscriber requests reliable"
        ],
    }
    assert report.pools == ["Drone", "Tractor (multi-instance)"]
    assert not report.problems and not report.ok and not report.notes


def test_compatible_configuration_passes(models, tmp_path):
    # figure 5.14b: both weed_position signals reliable; the other pairs fixed as well
    text = (
        (models / "qos.bpmn")
        .read_text()
        .replace('value="best_effort"', 'value="reliable"')
        .replace('name="durability" value="volatile"', 'name="durability" value="transient_local"')
        .replace('name="deadline" value="5"', 'name="deadline" value="1.5"')
    )
    path = tmp_path / "fixed.bpmn"
    path.write_text(text)
    report = check(parse(path))
    assert report.ok and len(report.pairs) == 3


def test_type_mismatch_and_lonely_topics_are_reported(models, tmp_path):
    text = (
        (models / "qos.bpmn")
        .read_text()
        .replace(
            'std_msgs/msg/String" />\n        <qos:policy name="reliability" value="Best',
            'std_msgs/msg/Int32" />\n        <qos:policy name="reliability" value="Best',
        )
    )
    text = text.replace(
        'id="t_position" name="tractor_position"', 'id="t_position" name="tractor_pose"'
    )
    path = tmp_path / "types.bpmn"
    path.write_text(text)
    report = check(parse(path))
    closest = next(p for p in report.pairs if p.publisher.topic == "/closest_tractor")
    assert closest.reasons == (
        "type: the publisher sends std_msgs/msg/String, the subscriber expects std_msgs/msg/Int32",
    )
    assert report.notes == [
        "/tractor_pose: thrown by Tractor t_position (tractor_pose) but caught by no pool",
        "/tractor_position: caught by Drone d_position (tractor_position) but thrown by no pool "
        "(published from outside?)",
    ]
