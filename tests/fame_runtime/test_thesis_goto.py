"""The authors' GoTo building block (fame-ros ``GoTo.bpmn``) run on its own, with a robot
whose odometry says it stands exactly on its target: its loop still never ends. *Check
Position* sets ``reached = false``, subscribes to ``odom`` and calls ``next()`` at once; the
gateway *destination reached?* reads ``reached`` in the same instant, before any odometry
message can run the callback, and the callback's ``reached = true`` is reset by the next
pass. FAME's engine runs a script's ``next()`` and the gateway's conditions in one dispatch
too (bpmn-engine), so no engine lets this GoTo complete."""

import pytest
from fame_suite import build, trace

ODOM = "nav_msgs/msg/Odometry"


def on_target(x: float, y: float) -> dict:
    return {"pose": {"pose": {"position": {"x": x, "y": y, "z": 0.0}}}}


@pytest.fixture
def goto(fame_models):
    return fame_models / "fame-ros" / "GoTo.bpmn"


def test_goto_never_completes_even_standing_on_its_target(goto, fame_models):
    mission, tags = build(
        goto,
        variables={"goto": {"x_target": 1.0, "y_target": 2.0}},
        library=fame_models / "fame-ros",
    )
    engine = mission.engines["goto"]
    seen_reached = []

    def odometry(step: int) -> None:
        mission.bus.publish("/goto/odom", on_target(1.0, 2.0), msgtype=ODOM)
        if step % 10 == 5:  # halfway between two passes of Check Position
            seen_reached.append(engine.variables.get("reached"))

    for step in range(1, 200):  # 10 Hz for 20 s
        mission.clock.call_later(step / 10, lambda s=step: odometry(s))
    mission.run(until=20.0)
    checks = [t.stamp for t in tags if t.activity == "check_position" and t.lifecycle == "start"]
    assert checks == [2.0 * n for n in range(1, 11)]  # every 2 s (wait2sec), 10 passes
    # before the first pass nobody set reached; between two passes the callback did find the
    # robot on its target ...
    assert seen_reached[:2] == [None, None] and all(seen_reached[2:]), seen_reached
    # ... yet the gateway only ever read the reset value: Stop never ran, GoTo never ended
    activities = {t.activity for t in tags}
    assert "stop" not in activities and engine.completed == 0
    assert trace(tags)[:4] == [
        (0.0, "goto", "navigate", "start"),
        (0.0, "goto", "navigate", "complete"),
        (2.0, "goto", "wait2sec", "start"),
        (2.0, "goto", "wait2sec", "complete"),
    ]
