import pytest

from robotale.fame_runtime.labels import (
    activity_label,
    catches,
    element_label,
    error_name,
    signal_name,
    signal_topic,
)
from robotale.fame_runtime.model import EventDefinition, Node


@pytest.mark.parametrize(
    ("name", "label"),
    [
        ("Take Off", "take_off"),
        ("ReturnToBase", "return_to_base"),
        ("GoTo", "go_to"),
        ("Cut grass", "cut_grass"),
        ("weed_position!", "weed_position!"),
        ("closest_tractor ?", "closest_tractor?"),
        ("I'm the closest tractor?", "i_m_the_closest_tractor?"),
        ("  Update   Closest ", "update_closest"),
    ],
)
def test_activity_label(name, label):
    assert activity_label(name) == label


def test_unnamed_element_is_tagged_with_its_id():
    assert activity_label(None, "Activity_0ecyw37") == "Activity_0ecyw37"
    assert activity_label("  ", "Event_1") == "Event_1"


def _signal(kind: str, name: str = "", signal: str = "") -> Node:
    return Node("Event_1", kind, name, events=[EventDefinition("signal", "Signal_1", signal)])


def _error(kind: str, name: str = "", error: str = "") -> Node:
    return Node("Event_2", kind, name, events=[EventDefinition("error", "Error_1", error)])


@pytest.mark.parametrize(
    ("kind", "label"),
    [
        ("intermediateThrowEvent", "weed_position!"),
        ("endEvent", "weed_position!"),
        ("intermediateCatchEvent", "weed_position?"),
        ("startEvent", "weed_position?"),
        ("boundaryEvent", "weed_position?"),
    ],
)
def test_a_signal_event_is_its_signal_sent_or_received(kind, label):
    assert element_label(_signal(kind, "Weed Position")) == label
    assert catches(_signal(kind)) == label.endswith("?")


def test_a_signal_is_named_by_the_event_else_by_its_signal():
    named = _signal("intermediateCatchEvent", " closest_tractor ? ", "ignored")
    assert signal_name(named) == "closest_tractor"
    assert signal_topic(named) == "/closest_tractor"
    unnamed = _signal("intermediateThrowEvent", "", "tractor position")
    assert signal_name(unnamed) == "tractor_position"
    assert element_label(unnamed) == "tractor_position!"
    # a thrown event written with the receiving suffix still sends
    assert element_label(_signal("endEvent", "weedFound?")) == "weed_found!"


def test_a_signal_topic_keeps_a_leading_slash_and_none_is_empty():
    assert signal_topic(_signal("intermediateThrowEvent", "/robot/ping")) == "/robot/ping"
    assert signal_topic(_signal("intermediateThrowEvent")) == ""


def test_an_error_event_is_its_error_else_its_name_else_its_id():
    assert error_name(_error("boundaryEvent", "Battery", "Low  Battery")) == "Low_Battery"
    assert element_label(_error("boundaryEvent", "Battery", "Low  Battery")) == "low_battery"
    assert element_label(_error("endEvent", "Abort Mission")) == "abort_mission"
    assert error_name(_error("endEvent")) == ""
    assert element_label(_error("endEvent")) == "Event_2"


def test_other_elements_are_their_name():
    assert element_label(Node("Task_1", "callActivity", "ReturnToBase")) == "return_to_base"
    timer = Node("Event_3", "intermediateCatchEvent", "Wait 5 s", events=[EventDefinition("timer")])
    assert element_label(timer) == "wait_5_s"
    assert element_label(Node("Gateway_1", "exclusiveGateway")) == "Gateway_1"
