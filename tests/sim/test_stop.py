"""The stop-distance experiment of thesis 5.3.5, simulated (``robotale simulate stop``): the
FAME model's stop goes out later than direct code's by what the engine's work costs, so the
car halts that much closer to the wall; braking takes more distance at higher speed."""

from __future__ import annotations

import io
from dataclasses import replace
from pathlib import Path

import pytest
from simbags import manifest, record

from robotale.cli import main
from robotale.commands.simulate import simulate_command
from robotale.errors import InputError
from robotale.fame_runtime.clock import EngineCost
from robotale.sim import scenarios
from robotale.sim.stopping import gap, variant_world
from robotale.sim.worldspec import World, load_world

ROUNDING = 1e-4  # the manifest's final positions are rounded to 0.1 mm


@pytest.fixture(scope="module")
def stop_world() -> World:
    return load_world(scenarios.world_file("stop"))


def exact_sensor(world: World) -> World:
    """The world with a sensor that reads exactly and never loses a reading."""
    car = world.robots[0]
    sensor = replace(car.range, noise=0.0, dropout=0.0)
    return replace(world, robots=(replace(car, range=sensor),))


def halted(world: World, variant: str, speed: float, folder: Path, seed: int = 5) -> float:
    """Metres between the wall and the halted car in one run."""
    run = manifest(record(variant_world(world, variant, speed), folder / variant, seed=seed))
    assert run["outcome"]["status"] == "ended", run["outcome"]
    assert run["failures"] == []
    return gap(world, run)


def tick_slack(world: World, speed: float) -> float:
    """A command takes effect at the next physics step: the two stops may differ by one."""
    return speed / world.physics_rate + 2 * ROUNDING


@pytest.mark.parametrize("speed", [0.8, 1.0])
def test_fame_stops_later_than_direct_code_by_engine_cost_times_speed(stop_world, tmp_path, speed):
    script = 0.05  # the script computing the stop: 5 cm at 1 m/s
    world = replace(stop_world, engine_cost=EngineCost(script=script))
    fame = halted(world, "fame", speed, tmp_path)
    direct = halted(world, "direct", speed, tmp_path)
    assert direct - fame == pytest.approx(script * speed, abs=tick_slack(world, speed))


def test_every_configured_cost_on_the_path_counts(stop_world, tmp_path):
    """The shipped costs: the condition on the range reading, the script and its step (the
    catch event fires outside a step; the call activity sends at the start of its own)."""
    cost = stop_world.engine_cost
    reaction = cost.condition + cost.script + cost.step
    speed = 1.0
    fame = halted(stop_world, "fame", speed, tmp_path)
    direct = halted(stop_world, "direct", speed, tmp_path)
    assert direct - fame == pytest.approx(reaction * speed, abs=tick_slack(stop_world, speed))


def test_without_engine_cost_fame_and_direct_code_stop_alike(stop_world, tmp_path):
    world = replace(stop_world, engine_cost=None)
    fame = halted(world, "fame", 1.0, tmp_path)
    direct = halted(world, "direct", 1.0, tmp_path)
    assert fame == pytest.approx(direct, abs=tick_slack(world, 1.0))


def test_the_stop_distance_grows_with_speed_by_the_braking_distance(stop_world, tmp_path):
    world = exact_sensor(stop_world)
    car = world.robots[0]
    braking = car.max_force / car.mass  # m/s2 (the tyres grip more: friction * g = 7.8)
    slow = halted(world, "direct", 0.8, tmp_path / "slow")
    fast = halted(world, "direct", 1.0, tmp_path / "fast")
    assert fast < slow
    # braking takes v^2 / 2a; where the reading first falls under 0.5 m varies by up to one
    # sensor period's travel at either speed
    extra = (1.0**2 - 0.8**2) / (2 * braking)
    sensed = 1.0 / world.control_rate
    assert slow - fast == pytest.approx(extra, abs=1.0 * sensed + 0.01)
    # and each halts short of the wall, past the point where it was told to stop
    for speed, halt in ((0.8, slow), (1.0, fast)):
        stopping = 0.5 - halt
        assert speed**2 / (2 * braking) <= stopping + 0.01
        assert stopping <= speed**2 / (2 * braking) + speed * (sensed + world.latency) + 0.02


def test_simulate_stop_prints_the_table_beside_the_thesis_figures(stop_world, tmp_path):
    out = io.StringIO()
    status = simulate_command(
        "stop", runs=1, out_dir=tmp_path / "stop", workers=0, quiet=True, out=out
    )
    text = out.getvalue()
    assert status == 0, text
    lines = text.splitlines()
    for speed in ("0.8", "0.9", "1.0"):  # speed, FAME, direct code, FAME later by (cm)
        row = next(line.split() for line in lines if line.strip().startswith(f"{speed} m/s"))
        fame, direct, later = float(row[2]), float(row[3]), float(row[4])
        assert 0 < fame < 50 and 0 < direct < 50  # halted short of the wall, past 0.5 m
        assert later == pytest.approx(direct - fame, abs=0.011)
    for variant in ("fame", "direct"):
        for speed in ("0.8", "0.9", "1"):
            assert (tmp_path / "stop" / f"{variant}_{speed}" / "run_0001").is_dir()
    # thesis 5.3.5, the text on Figure 5.19: FAME stops at 14.09 cm, compiled code at
    # 14.67 cm (simulated, 0.58 cm apart) and at 39.07 and 40.18 cm (physical, 1.11 cm apart)
    simulated = next(line for line in lines if line.strip().startswith("simulated"))
    physical = next(line for line in lines if line.strip().startswith("physical"))
    assert simulated.split() == ["simulated", "14.09", "14.67", "0.58", "cm"]
    assert physical.split() == ["physical", "39.07", "40.18", "1.11", "cm"]


@pytest.mark.slow
def test_the_table_agrees_with_the_runs_it_summarises(stop_world, tmp_path):
    out = io.StringIO()
    simulate_command("stop", runs=2, out_dir=tmp_path / "stop", workers=0, quiet=True, out=out)
    lines = out.getvalue().splitlines()
    row = next(line for line in lines if line.strip().startswith("1.0 m/s"))
    gaps = {
        variant: [
            gap(stop_world, manifest(tmp_path / "stop" / f"{variant}_1" / f"run_000{i}"))
            for i in (1, 2)
        ]
        for variant in ("fame", "direct")
    }
    cells = row.split()
    fame_mean = sum(gaps["fame"]) / 2 * 100
    direct_mean = sum(gaps["direct"]) / 2 * 100
    assert float(cells[2]) == pytest.approx(fame_mean, abs=0.006)
    assert float(cells[5]) == pytest.approx(direct_mean, abs=0.006)
    assert float(cells[8]) == pytest.approx(direct_mean - fame_mean, abs=0.011)


def test_engine_cost_in_a_world_file_is_checked(tmp_path):
    base = (scenarios.world_file("stop")).read_text(encoding="utf-8")
    for written, complaint in (
        ("engine_cost: {script: 0.002, think: 1}", "unknown key 'think'"),
        ("engine_cost: {script: -0.002}", "engine_cost.script is -0.002"),
        ("engine_cost: {script: 0.002, measured: 2}", "either measured or fixed costs"),
    ):
        path = tmp_path / "stop.yaml"
        path.write_text(
            base.replace(
                "engine_cost: {script: 0.002, condition: 0.0005, step: 0.0001}", written
            ).replace("model: stop.bpmn", f"model: {scenarios.model_file('stop')}"),
            encoding="utf-8",
        )
        with pytest.raises(InputError, match=complaint) as raised:
            load_world(path)
        assert str(raised.value).startswith(f"{path}: engine_cost")
    assert load_world(scenarios.world_file("stop")).engine_cost == EngineCost(
        script=0.002, condition=0.0005, step=0.0001
    )


def test_a_bad_engine_cost_flag_is_one_sentence(capsys):
    assert main(["simulate", "stop", "--engine-cost", "script=fast"]) == 1
    error = capsys.readouterr().err.strip()
    assert error.count("\n") == 0
    assert "--engine-cost 'script=fast'" in error and "KEY=SECONDS" in error


def test_with_fixed_engine_costs_the_same_seed_gives_the_same_bag(stop_world, tmp_path):
    world = variant_world(stop_world, "fame", 0.9)
    bags = [record(world, tmp_path / name, seed=11) for name in ("first", "second")]
    contents = [
        {p.name: p.read_bytes() for p in sorted(bag.iterdir()) if p.suffix != ".json"}
        for bag in bags
    ]
    assert contents[0] == contents[1] and any(n.endswith(".db3") for n in contents[0])
    runs = [{k: v for k, v in manifest(bag).items() if k != "wall_time"} for bag in bags]
    assert runs[0] == runs[1]
    assert runs[0]["settings"]["engine_cost"] == {
        "script": 0.002,
        "condition": 0.0005,
        "step": 0.0001,
    }
