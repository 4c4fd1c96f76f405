"""The thesis' physical scenario (section 5.3) from the authors' published files, unmodified:
REX (simple_scenario.bpmn's REX pool) explores with their Explore/Detect/GoTo building
blocks and its range sensor, throws ``target_found``, and DINGO starts on it, with REX's
position in its ``x_target``/``y_target`` (FAME's payload rule). DINGO then drives through
that position and never stops: the published GoTo cannot complete (see
tests/fame_runtime/test_thesis_goto.py), so Fire and ``done`` are never reached."""

from dataclasses import replace
from pathlib import Path

import pytest
from simbags import full_batteries, manifest, messages, record, seconds, tags

from robotale.cli import main
from robotale.sim.plans import adjust, check, resolve_world

NOISY = {"activate_sensor", "identify_target", "wait2sec", "check_position", "Event_timer2s"}


@pytest.fixture
def thesis(fame_models) -> Path:
    return fame_models / "fame-ros"


def target_ahead(world, *, time_limit: float):
    """The rexdingo world with both cars heading along +x on one line, DINGO 0.8 m behind REX,
    and the target on that line 1.4 m ahead of REX: the published GoTo only drives forward
    (0.1 m/s, never turning), so DINGO's way passes where REX saw the target."""
    robots = tuple(replace(r, start_jitter=0.0) for r in world.robots)
    objects = tuple(replace(o, area=((2.5, 2.5), (0.3, 0.3)), margin=0.0) for o in world.objects)
    bases = {
        "rex_base": replace(world.bases["rex_base"], position=(1.1, 0.3)),
        "dingo_base": replace(world.bases["dingo_base"], position=(0.3, 0.3)),
    }
    world = replace(world, robots=robots, objects=objects, bases={**world.bases, **bases})
    return full_batteries(adjust(world, time_limit=time_limit))


def test_published_rex_and_dingo_run_until_dingo_drives(thesis, tmp_path):
    world, _ = resolve_world("rexdingo", thesis / "simple_scenario.bpmn", None, thesis)
    world = target_ahead(world, time_limit=20.0)
    check(world)  # nothing the engine refuses, nothing the world lacks
    bag = record(world, tmp_path)
    assert manifest(bag)["outcome"] == {"status": "time limit", "reason": ""}
    log = tags(bag)
    steps = [(t.robot, t.activity, t.lifecycle) for t in log if t.activity not in NOISY]
    # Detect's first look (Identify Target, Activate Sensor) sees the target under 1.4 m;
    # its 2 s wait later, it throws target_found with REX's position, which starts DINGO
    assert steps == [
        ("rex", "explore", "start"),
        ("rex", "compute_points", "start"),
        ("rex", "compute_points", "complete"),
        ("rex", "get_point", "start"),
        ("rex", "get_point", "complete"),
        ("rex", "go_to", "start"),
        ("rex", "detect", "start"),
        ("rex", "navigate", "start"),
        ("rex", "navigate", "complete"),
        ("rex", "target_found!", "start"),
        ("rex", "target_found!", "complete"),
        ("rex", "detect", "complete"),
        ("dingo", "target_found?", "start"),
        ("dingo", "target_found?", "complete"),
        ("dingo", "go_to", "start"),
        ("dingo", "navigate", "start"),
        ("dingo", "navigate", "complete"),
    ]
    found = next(t for t in log if t.activity == "target_found!")
    assert seconds(found) - seconds(log[0]) == pytest.approx(2.0)
    assert found.payload == '{"x":1.1,"y":0.3,"z":0}'  # REX's odometry when it saw the target
    # DINGO's Check Position runs every 2 s; at some of them its odometry is within GoTo's
    # 0.2 m of x_target/y_target (REX's position), yet GoTo never completes: no Stop, no Fire
    checks = [seconds(t) for t in log if t.robot == "dingo" and t.activity == "check_position"]
    assert len(checks) >= 2 * 8
    odometry = [
        (ns / 1e9, m.pose.pose.position.x, m.pose.pose.position.y)
        for _, ns, m in messages(bag, {"/dingo/odom"})
    ]
    on_target = [
        t for t in checks[::2]
        if any(abs(at - t) < 0.3 and abs(x - 1.1) <= 0.2 and abs(y - 0.3) <= 0.2
               for at, x, y in odometry)
    ]  # fmt: skip
    assert on_target, "DINGO never passed where REX saw the target"
    assert not {"stop", "fire", "done!"} & {t.activity for t in log}
    targets = manifest(bag)["targets"]
    assert (targets["found"], targets["destroyed"]) == (1, 0)
    assert "/target_found" in {topic for topic, _, _ in messages(bag, None)}


def test_check_of_the_published_rex_dingo_names_nothing_lacking(thesis, capsys):
    # REX's target_found is thrown by its Detect building block: no robot must publish it
    world = Path(__file__).resolve().parents[2] / "robotale" / "sim" / "scenarios"
    code = main(["fame", "check", str(thesis / "simple_scenario.bpmn"), "--library",
                 str(thesis), "--world", str(world / "rexdingo.yaml")])  # fmt: skip
    out = capsys.readouterr().out
    assert code == 0, out
    assert "simulation lacks" not in out and "structure: ok" in out
