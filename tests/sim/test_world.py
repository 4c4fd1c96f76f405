"""World files: read and checked, every mistake one sentence naming the file and the key; and
the world itself: batteries, charging, sensors."""

from __future__ import annotations

from pathlib import Path

import pytest

from robotale.errors import InputError
from robotale.sim.battery import Battery
from robotale.sim.setup import MIN_GAP, draw
from robotale.sim.worldspec import load_world

GOOD = """model: mission.bpmn
field: [6, 4]
bases:
  home: {position: [0, 0]}
robots:
  rover: {kind: ground, base: home, count: 3, spacing: [0, 1]}
weeds: {count: [2, 3]}
"""


def world_file(folder: Path, text: str) -> Path:
    path = folder / "world.yaml"
    path.write_text(text, encoding="utf-8")
    return path


def test_a_world_file_reads_with_its_defaults(tmp_path):
    world = load_world(world_file(tmp_path, GOOD))
    assert world.model == tmp_path / "mission.bpmn"
    assert world.field == (6.0, 4.0)
    assert world.robot_names() == ["rover_1", "rover_2", "rover_3"]
    assert (world.time_limit, world.control_rate, world.record_rate) == (900.0, 10.0, 2.0)
    setup = draw(world, 11)
    assert [r.home for r in setup.robots] == [(0.0, 0.0), (0.0, 1.0), (0.0, 2.0)]
    assert sorted(r.phase for r in setup.robots) == [
        0.0,
        pytest.approx(1 / 3),
        pytest.approx(2 / 3),
    ]
    weeds = setup.objects
    assert 2 <= len(weeds) <= 3
    assert all(0.5 <= w.x <= 5.5 and 0.5 <= w.y <= 3.5 for w in weeds)
    for i, a in enumerate(weeds):
        for b in weeds[i + 1 :]:
            assert ((a.x - b.x) ** 2 + (a.y - b.y) ** 2) ** 0.5 >= MIN_GAP
    assert draw(world, 11) == setup and draw(world, 12) != setup


@pytest.mark.parametrize(
    ("change", "message"),
    [
        (("field: [6, 4]", "feld: [6, 4]"), "the file has unknown key 'feld'"),
        (("kind: ground", "kind: boat"), "robots.rover.kind is 'boat'; it must be one of"),
        (("base: home,", "base: shed,"), "robots.rover.base is 'shed', which is not one of"),
        (("count: 3", "count: 0"), "robots.rover.count is 0; it must be a whole number >= 1"),
        (("field: [6, 4]", "field: [6]"), "field is [6]; it must be a list of 2 numbers"),
        (("count: [2, 3]", "count: [3, 2]"), "weeds.count is [3, 2]; it must be [low, high]"),
        (("count: [2, 3]", "count: 400"), "there is no room for 400 weeds"),
        (("field: [6, 4]", "field: [6, 4]\nstart: yesterday"), "start 'yesterday' is not an ISO"),
        (("model: mission.bpmn\n", ""), "names no mission model (key 'model')"),
        (("bases:", "bases: ["), "not valid YAML"),
    ],
)
def test_mistakes_in_a_world_file_name_the_file_and_the_key(tmp_path, change, message):
    path = world_file(tmp_path, GOOD.replace(*change))
    with pytest.raises(InputError) as error:
        draw(load_world(path), 1)
    assert str(error.value).startswith(f"{path}: ")
    assert message in str(error.value)


def test_a_battery_drains_with_time_and_motion_charges_on_its_base_and_warns_when_low():
    battery = Battery(0.3, 0.001, 0.01, 0.05, 0.2, 10.0)
    assert not battery.step(1.0, 1.0, False, 0.0)
    assert battery.level == pytest.approx(0.3 - 0.011)
    warned = [battery.step(1.0, 1.0, False, float(t)) for t in range(1, 30)]
    assert battery.level < 0.2
    first = warned.index(True) + 1
    assert [t for t, w in enumerate(warned, start=1) if w] == list(range(first, 30, 10))
    assert not battery.step(1.0, 0.0, True, 30.0)  # charging: no warning
    assert battery.charging and battery.message(30.0, "rover")["power_supply_status"] == 1
    battery.fault_drain = 0.5
    battery.step(1.0, 0.0, True, 31.0)
    assert not battery.charging  # a fault drains even on the charger
    battery.step(10.0, 0.0, False, 41.0)
    assert battery.empty and battery.message(41.0, "rover")["percentage"] == 0.0
