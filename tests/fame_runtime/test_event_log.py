"""A mission run with no hand-placed tags yields a TALE event log: pm4py reads the tags as
they are and discovers the directly-follows graph the models imply."""

import pandas as pd
import pm4py
from fame_suite import run

from robotale.fame_runtime.bus import InProcessBus
from robotale.fame_runtime.clock import SimClock
from robotale.fame_runtime.mission import Mission
from robotale.fame_runtime.tags import TAG_TYPE, Tag, bus_sink


def as_log(tags: list[Tag]) -> pd.DataFrame:
    """Completed activities, one case per robot (the view of a robot's own behaviour)."""
    rows = [
        {
            "case:concept:name": t.robot,
            "concept:name": t.activity,
            "time:timestamp": pd.Timestamp(t.stamp, unit="s", tz="UTC"),
            "lifecycle:transition": t.lifecycle,
        }
        for t in tags
        if t.lifecycle == "complete"
    ]
    return pd.DataFrame(rows)


def test_tags_of_a_mission_are_an_event_log_pm4py_discovers_from():
    _, tags = run("signals.bpmn", robots=["drone", "tractor_1", "tractor_2"], latency=0.5)
    dfg, starts, ends = pm4py.discover_dfg(as_log(tags))
    assert dfg == {
        ("1_s", "detect_weed"): 1,
        ("detect_weed", "weed_position!"): 1,
        ("weed_position!", "tractor_position?"): 1,
        ("weed_position?", "tractor_position!"): 2,
    }
    assert starts == {"1_s": 1, "weed_position?": 2}
    assert ends == {"tractor_position?": 1, "tractor_position!": 2}


def test_messages_pair_every_receive_with_its_send():
    _, tags = run("signals.bpmn", robots=["drone", "tractor_1", "tractor_2"], latency=0.5)
    sends = {t.msg_id: t for t in tags if t.msg_role == "send" and t.lifecycle == "start"}
    receives = [t for t in tags if t.msg_role == "receive" and t.lifecycle == "start"]
    assert [(sends[r.msg_id].robot, r.robot, r.activity) for r in receives] == [
        ("drone", "tractor_1", "weed_position?"),
        ("drone", "tractor_2", "weed_position?"),
        ("tractor_1", "drone", "tractor_position?"),
    ]
    assert all(r.payload == sends[r.msg_id].payload for r in receives)


def test_bus_sink_publishes_tags_on_the_robot_tag_topic(models):
    clock = SimClock()
    bus = InProcessBus(clock)
    recorded = []
    bus.tap(lambda envelope: recorded.append(envelope) if envelope.msgtype == TAG_TYPE else None)
    Mission(models / "parallel.bpmn", clock=clock, bus=bus, tag_sink=bus_sink(bus)).run()
    assert {e.topic for e in recorded} == {"/rover/tag"}
    assert [e.data.activity for e in recorded][:2] == ["b", "b"]
    assert all(e.stamp == e.data.stamp for e in recorded)
