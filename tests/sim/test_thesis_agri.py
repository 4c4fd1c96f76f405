"""The thesis authors' agri collaboration, unmodified, run against the simulated drone and
tractors: their JavaScript building blocks (TakeOff, Explore, GoTo, Detect, Land ...) drive
the robots through the topics the thesis' robots expose (odom, range, cmd_vel, the Tello's
``tello_action`` service), and the drone's camera tells the mission ``weed_found``."""

from dataclasses import replace
from pathlib import Path

import pytest
from simbags import full_batteries, manifest, messages, record, tags

from robotale.cli import main
from robotale.sim import scenarios
from robotale.sim.plans import adjust, check, resolve_world

FIGURE_7_4 = [  # the drone's DFG in the thesis (figure 7.4), up to its first closest tractor
    "take_off",
    "explore",
    "weed_found?",
    "weed_position!",
    "tractor_position?",
    "closest_tractor!",
]


@pytest.fixture
def thesis(fame_models) -> Path:
    return fame_models / "fame-ros"


def straight_flight(world, *, time_limit: float):
    """The agri world with the drone heading along +x from its base at (0, 5) and two weeds
    on that line: the published GoTo only drives forward (0.1 m/s, never turning), so the
    drone's camera sees what lies ahead of it."""
    robots = tuple(replace(r, start_jitter=0.0) if r.kind == "drone" else r for r in world.robots)
    objects = tuple(
        replace(o, area=((1.5, 3.0), (4.6, 5.4)), margin=0.0) if o.kind == "weed" else o
        for o in world.objects
    )
    world = replace(world, robots=robots, objects=objects)
    return full_batteries(adjust(world, counts={"tractor": 2}, weeds=(2, 2), time_limit=time_limit))


def test_the_published_agri_model_runs_with_the_simulated_robots(thesis, tmp_path):
    world, _ = resolve_world("agri", thesis / "agri.bpmn", None, thesis)
    world = straight_flight(world, time_limit=90.0)
    check(world)  # nothing the engine refuses, no unknown message type
    bag = record(world, tmp_path)
    run = manifest(bag)
    assert run["outcome"]["reason"] == ""  # no crash: the time limit ends the endless Explore
    drone = [t.activity for t in tags(bag) if t.robot == "drone" and t.lifecycle == "start"]
    seen = [a for a in drone if a in FIGURE_7_4]
    firsts = [seen.index(a) for a in FIGURE_7_4]
    assert firsts == sorted(firsts), seen  # each first appears in the figure's order
    # the thesis' building blocks ran, not robotale's skills: their own activities are tagged
    assert {"check_altitude", "send_take_off", "compute_points", "navigate"} <= set(drone)
    assert {t for t, _, _ in messages(bag, None)} >= {"/weed_found", "/weed_position"}
    # the published TakeOff only calls the Tello's action service (no /drone/takeoff): the
    # simulated drone serving it is why the drone flies
    assert run["robots_final"]["drone"]["z"] == pytest.approx(1.5)
    tractors = {t.robot for t in tags(bag) if t.activity == "tractor_position!"}
    assert tractors == {"tractor_1", "tractor_2"}  # both answered the weed_position signal


def test_simulate_command_takes_the_library(thesis, tmp_path, capsys):
    code = main(
        [
            "simulate",
            "agri",
            "--model",
            str(thesis / "agri.bpmn"),
            "--library",
            str(thesis),
            "--time-limit",
            "20",
            "--weeds",
            "2",
            "--workers",
            "0",
            "--quiet",
            "--out",
            str(tmp_path / "runs"),
        ]
    )
    out = capsys.readouterr().out
    assert code == 0, out
    assert "1 run of agri" in out and "1 time limit" in out
    drone = [t.activity for t in tags(tmp_path / "runs" / "run_0001") if t.robot == "drone"]
    assert drone[:3] == ["take_off", "check_altitude", "check_altitude"]


def test_a_missing_library_folder_is_one_sentence(thesis, tmp_path, capsys):
    code = main(["simulate", "agri", "--library", str(tmp_path / "nowhere"), "--quiet"])
    assert code != 0
    assert capsys.readouterr().err == (
        f"robotale: --library {tmp_path / 'nowhere'}: there is no such folder\n"
    )


def test_check_names_what_the_world_lacks_before_anything_runs(thesis, tmp_path, capsys):
    # agri's world without the drone camera's weed_found signal, and the tractors' blade
    # commanded with a Wrench by the published Tractor_1 (robotale's blade takes a Float64)
    world = tmp_path / "world.yaml"
    agri = (Path(scenarios.__file__).parent / "agri.yaml").read_text(encoding="utf-8")
    world.write_text(agri.replace(", signal: weed_found", ""))
    code = main(
        [
            "fame",
            "check",
            str(thesis / "agri.bpmn"),
            "--library",
            str(thesis),
            "--world",
            str(world),
        ]
    )
    out = capsys.readouterr().out
    assert code == 1
    assert out.splitlines()[-2:] == [
        "simulation lacks: 1",
        "  startEvent Event_0ndvs1n (weed_found) needs a robot that publishes /weed_found "
        "(geometry_msgs/msg/Vector3) for drone",
    ]
    code = main(["fame", "check", str(thesis / "Tractor_1.bpmn"), "--library", str(thesis),
                 "--world", str(world)])  # fmt: skip
    out = capsys.readouterr().out.splitlines()
    # alone, Tractor_1's pool also waits for the drone's signals: nobody in the world sends them
    assert out[out.index("simulation lacks: 3") + 1 :] == [
        "  script task Activity_1r1r1y9 (Cut grass) needs a robot that subscribes to "
        "/tractor_1/blade_force (geometry_msgs/msg/Wrench) for tractor_1, but the simulated "
        "robot's is std_msgs/msg/Float64",
        "  intermediateCatchEvent Event_closest_1 (closest_tractor) needs a robot that publishes "
        "/closest_tractor (std_msgs/msg/String) for tractor_1",
        "  startEvent Event_weed1 (weed_position) needs a robot that publishes /weed_position "
        "(geometry_msgs/msg/Vector3) for tractor_1",
    ]
