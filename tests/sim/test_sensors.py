"""Sensor models: range noise and dropouts, camera detection probability by distance and false
positives, odometry drift; each as configured, repeatable for a seed, exact when switched
off."""

from __future__ import annotations

import statistics
from pathlib import Path

import pytest

from robotale.errors import InputError
from robotale.fame_runtime.bus import InProcessBus
from robotale.fame_runtime.clock import SimClock
from robotale.sim.robots import FLYING, TWIST
from robotale.sim.setup import Placed, RobotStart, Setup
from robotale.sim.world import SimWorld
from robotale.sim.worldspec import load_world

WORLD = """model: none.bpmn
field: [20, 8]
bases:
  home: {{position: [1, 4]}}
robots:
  rover: {{kind: ground, base: home, max_speed: 1.0, odom_drift: {drift},
          range: {{max_range: 4.0, rays: 1, noise: {noise}, dropout: {dropout}}}}}
  drone: {{kind: drone, base: home,
          camera: {{fov: 90, detection: {detection}, falloff: {falloff},
                   false_positives: {phantoms}}}}}
obstacles:
  wall: {{position: [5, 4], size: [0.4, 4, 0.5]}}
weeds: {{count: 0}}
"""
OFF = {"drift": 0, "noise": 0, "dropout": 0, "detection": 1, "falloff": 0, "phantoms": 0}
SECONDS = 200.0  # 2000 control steps


def run(tmp_path: Path, seed: int = 1, seconds: float = SECONDS, drive: float = 0.0, **model):
    """Run a world with the rover 2.7 m before the wall's face and the drone 2 m above a weed
    at 1 m beside it; every message published, by topic."""
    path = tmp_path / "world.yaml"
    path.write_text(WORLD.format(**{**OFF, **model}), encoding="utf-8")
    robots = (
        RobotStart("rover", "rover", 2.0, 4.0, 0.0, (2.0, 4.0), 1.0, 0.0, 0.0),
        RobotStart("drone", "drone", 10.0, 2.0, 0.0, (10.0, 2.0), 1.0, 0.0, 0.0, phase=0.5),
    )
    weed = Placed("weed", "weed_1", 11.0, 2.0)
    clock, published = SimClock(0.0), {}
    bus = InProcessBus(clock)
    bus.tap(lambda e: published.setdefault(e.topic, []).append(e.data))
    sim = SimWorld(load_world(path), Setup(seed, robots, (weed,)), clock=clock, bus=bus)
    drone = sim.robots["drone"]
    drone.pose.z, drone.flight = 2.0, FLYING
    try:
        sim.start()
        if drive:
            bus.publish("/rover/cmd_vel", {"linear": {"x": drive}}, msgtype=TWIST)
        clock.run(until=seconds)
        return published, sim
    finally:
        sim.close()


def ranges(published) -> list[float]:
    return [m["range"] for m in published["/rover/range"]]


def test_range_noise_and_dropouts_are_as_configured_and_exact_when_off(tmp_path):
    truth = 5.0 - 0.2 - 2.0 - 0.3  # the wall's face less the rover's half length: 2.5 m
    exact = ranges(run(tmp_path)[0])
    assert exact and all(r == pytest.approx(truth, abs=1e-3) for r in exact)
    noisy = ranges(run(tmp_path, noise=0.05, dropout=0.2)[0])
    lost = [r for r in noisy if r == 4.0]
    kept = [r for r in noisy if r != 4.0]
    assert len(lost) / len(noisy) == pytest.approx(0.2, abs=0.03)
    assert statistics.mean(kept) == pytest.approx(truth, abs=0.01)
    assert statistics.stdev(kept) == pytest.approx(0.05, abs=0.005)
    assert ranges(run(tmp_path, noise=0.05, dropout=0.2)[0]) == noisy  # seeded
    assert ranges(run(tmp_path, seed=2, noise=0.05, dropout=0.2)[0]) != noisy


def detections(published) -> list[str]:
    return [m["header"]["frame_id"] for m in published.get("/drone/detection", [])]


def test_camera_detection_probability_falls_with_distance_and_phantoms_appear(tmp_path):
    assert detections(run(tmp_path)[0]) == ["weed_1"] * 2000  # one a frame, nothing else
    # the weed is sqrt(1 + 4) m from the camera
    chance = 0.9 - 0.2 * 5**0.5
    seen = detections(run(tmp_path, detection=0.9, falloff=0.2)[0])
    assert set(seen) == {"weed_1"}
    assert len(seen) / 2000 == pytest.approx(chance, abs=0.03)
    phantoms = [d for d in detections(run(tmp_path, phantoms=0.5)[0]) if d != "weed_1"]
    assert len(phantoms) / SECONDS == pytest.approx(0.5, abs=0.1)
    assert all(p.startswith("phantom_") for p in phantoms)


def test_odometry_drifts_with_distance_travelled(tmp_path):
    def error(**model) -> float:
        published, sim = run(tmp_path, seconds=2.0, drive=1.0, **model)
        odom = published["/rover/odom"][-1]["pose"]["pose"]["position"]
        rover = sim.robots["rover"].pose
        return ((odom["x"] - rover.x) ** 2 + (odom["y"] - rover.y) ** 2) ** 0.5

    assert error() == pytest.approx(0.0, abs=1e-6)
    drifted = [error(drift=0.1, seed=seed) for seed in range(1, 41)]
    # a random walk of 0.1 m per root metre over about 2 m, in x and y: the error's root mean
    # square is 0.1 * sqrt(2) * sqrt(2)
    rms = statistics.mean(d**2 for d in drifted) ** 0.5
    assert rms == pytest.approx(0.2, rel=0.35)
    assert error(drift=0.1, seed=3) == drifted[2]


@pytest.mark.parametrize(
    ("model", "message"),
    [
        ({"dropout": 1.5}, "robots.rover.range.dropout is 1.5; a probability is at most 1"),
        ({"detection": -0.1}, "robots.drone.camera.detection is -0.1; it must not be negative"),
        ({"drift": "lots"}, "robots.rover.odom_drift is 'lots', not a number"),
    ],
)
def test_mistakes_in_the_sensor_models_name_the_key(tmp_path, model, message):
    path = tmp_path / "world.yaml"
    path.write_text(WORLD.format(**{**OFF, **model}), encoding="utf-8")
    with pytest.raises(InputError) as error:
        load_world(path)
    assert str(error.value).startswith(f"{path}: ") and message in str(error.value)
