"""Engine time counts: on a simulated clock with an engine cost, the time an engine spends in
scripts, conditions and token steps passes on the clock before what follows them happens,
while the rest of the world goes on."""

from __future__ import annotations

from pathlib import Path

import pytest

from robotale.fame_runtime.bus import InProcessBus
from robotale.fame_runtime.clock import EngineCost, SimClock
from robotale.fame_runtime.engine import Engine
from robotale.fame_runtime.parser import parse

RANGE = "sensor_msgs/msg/Range"
SENSED = 1.0  # when the obstacle comes into reach


class Stopper:
    """A range-triggered stop (``models/stopper.bpmn``: a conditional event on the range
    sensor, a script computing the command, a signal end event sending it, as
    ``benchmarks/dds_latency.py``'s stopper does over DDS) on a simulated clock."""

    def __init__(self, model: Path, cost: EngineCost | None) -> None:
        self.clock = SimClock(0.0, engine_cost=cost)
        self.bus = InProcessBus(self.clock, latency=0.0)
        self.sent: list[float] = []  # when the stop command went out
        self.tags: list = []
        self.bus.tap(self._sending)
        self.engine = Engine(
            parse(model).processes["stopper"],
            robot="robot",
            bus=self.bus,
            clock=self.clock,
            tag_sink=self.tags.append,
        )
        self.engine.start()

    def _sending(self, envelope) -> None:
        if envelope.topic == "/cmd_vel":
            self.sent.append(self.clock.now())

    def reading(self, when: float, distance: float) -> None:
        publish = self.bus.publish
        self.clock.call_at(
            when, lambda: publish("/range", {"range": distance}, msgtype=RANGE, sender="sonar")
        )

    def run(self, until: float = SENSED + 5.0) -> Stopper:
        self.clock.run(until=until)
        return self


@pytest.fixture
def model(models: Path) -> Path:
    return models / "stopper.bpmn"


def sensed(model: Path, cost: EngineCost | None) -> Stopper:
    """The stopper once an obstacle was read at 0.3 m at SENSED."""
    stopper = Stopper(model, cost)
    stopper.reading(SENSED, 0.3)
    return stopper.run()


def test_a_script_cost_delays_the_command_it_computes_by_exactly_that(model):
    cost = 0.025
    assert sensed(model, EngineCost(script=cost)).sent == [pytest.approx(SENSED + cost, abs=1e-12)]


def test_condition_and_step_costs_add_up_along_the_path(model):
    script, condition, step = 0.002, 0.0005, 0.0001
    stopper = sensed(model, EngineCost(script=script, condition=condition, step=step))
    # at SENSED the condition is evaluated (busy until + condition); the catch fires, the
    # token takes the script's step (script + step), then the end event's step sends
    assert stopper.sent == [pytest.approx(SENSED + condition + script + step, abs=1e-12)]


def test_zero_costs_are_todays_engine_tag_for_tag(model):
    today, free = sensed(model, None), sensed(model, EngineCost())
    assert today.sent == [SENSED]  # no engine time: the stop goes out as the range arrives
    assert free.sent == today.sent
    assert free.tags == today.tags and len(today.tags) >= 6


def test_the_world_goes_on_while_the_engine_computes(model):
    stopper = Stopper(model, EngineCost(script=0.1))
    stopper.reading(SENSED, 0.3)
    seen: list[bool] = []  # per control tick: has the stop gone out?
    for tick in range(-5, 20):  # a control loop at 100 Hz, unaware of the engine
        stopper.clock.call_at(SENSED + tick / 100, lambda: seen.append(bool(stopper.sent)))
    stopper.run(SENSED + 1.0)
    # the ticks at SENSED + 0.00 .. 0.09 ran while the engine computed; the stop came after
    assert seen[5:15] == [False] * 10
    assert all(seen[16:])
    assert stopper.sent == [pytest.approx(SENSED + 0.1)]


def test_work_arriving_while_the_engine_computes_waits_for_it(model):
    """A reading that arrives while the engine still evaluates the previous one is evaluated
    after it: the engine has one processor."""
    stopper = Stopper(model, EngineCost(script=0.1, condition=0.01))
    stopper.reading(SENSED, 0.7)
    stopper.reading(SENSED + 0.005, 0.3)
    stopper.run()
    # far (0.01 from SENSED), then near queued behind it (0.01 more), then the script (0.1);
    # charged from its arrival instead, the stop would go out at SENSED + 0.115
    assert stopper.sent == [pytest.approx(SENSED + 0.01 + 0.01 + 0.1, abs=1e-12)]


def test_measured_mode_charges_the_wall_time_of_the_work(model, tmp_path):
    sleeper = tmp_path / "sleeper.bpmn"
    text = model.read_text(encoding="utf-8")
    sleeper.write_text(
        text.replace("command = 0.0", "import time\ntime.sleep(0.02)\ncommand = 0.0"),
        encoding="utf-8",
    )
    delay = sensed(sleeper, EngineCost(measured=2.0)).sent[0] - SENSED
    assert delay >= 2.0 * 0.02  # the script slept 20 ms of wall time, charged twice over
    assert delay < 2.0 * 2.0  # and not absurdly more (a loaded machine stays under 2 s)


def test_a_token_leaves_a_node_once_its_step_is_computed(model):
    stopper = Stopper(model, EngineCost(step=0.5))
    stopper.run(until=0.25)  # the start event's step is being computed
    assert stopper.engine.where() == ["startEvent go"] and not stopper.engine.idle
    stopper.run(until=0.75)  # from 0.5 the catch event, armed, is computed
    assert stopper.engine.where() == ["intermediateCatchEvent near"]
