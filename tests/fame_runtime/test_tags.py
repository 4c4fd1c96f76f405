import pytest

from robotale.fame_runtime.tags import activity_label


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
