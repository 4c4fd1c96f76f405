"""What the Model page paints: the engine's tags found again on the BPMN elements."""

from __future__ import annotations

import pytest

from robotale.fame_runtime.mission import Mission
from robotale.webapp.overlay import element_label


@pytest.mark.parametrize(
    "model",
    ["fame-modeler/rexdingo.bpmn", "fame-ros/tests/process_2.bpmn"],
)
def test_every_tag_the_engine_emits_is_the_label_of_an_element(fame_models, model):
    # The thesis' own models with signals thrown and caught, timers and unnamed tasks.
    tags = []
    mission = Mission(fame_models / model, tag_sink=tags.append)
    mission.run(until=600)
    assert len(tags) >= 12
    labels = {(a.robot, element_label(n)) for a in mission.assignments for n in a.process.walk()}
    assert {(t.robot, t.activity) for t in tags} <= labels
    assert any(t.activity.endswith("!") for t in tags) and any(
        t.activity.endswith("?") for t in tags
    )
