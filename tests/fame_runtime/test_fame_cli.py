"""``robotale fame check|split|run`` on real model files."""

import sys

import pytest
from fame_suite import PERSON

from robotale.cli import main
from robotale.fame_runtime.parser import parse


def test_check_reports_qos_and_fails_on_incompatible_pairs(models, capsys):
    assert main(["fame", "check", str(models / "qos.bpmn")]) == 1
    out = capsys.readouterr().out
    assert "structure: ok" in out
    assert "QoS: 3 publisher/subscriber pairs, 2 incompatible" in out
    assert (
        "/weed_position: Drone d_weed (weed_position) -> Tractor t_weed (weed_position): "
        "INCOMPATIBLE: reliability: the publisher offers best_effort, the subscriber requests "
        "reliable"
    ) in out


def test_check_passes_a_runnable_model(models, capsys):
    code = main(
        [
            "fame",
            "check",
            str(models / "calls.bpmn"),
            "--library",
            str(models / "library"),
            "--skills",
            str(models / "library" / "rover_skills.py"),
        ]
    )
    out = capsys.readouterr().out
    assert code == 0, out
    assert "structure: ok" in out and "QoS: 0 publisher/subscriber pairs" in out


def test_check_lists_what_the_engine_cannot_run(fame_models, capsys):
    assert main(["fame", "check", str(fame_models / "fame-modeler" / "example.bpmn")]) == 1
    out = capsys.readouterr().out
    assert "structure: the engine cannot run" in out
    model = fame_models / "fame-modeler" / "example.bpmn"
    assert (
        f"  {model}:100:5: Process_1: userTask Task_026c0id (Insert Card) needs a person" + PERSON
        in out
    )


def test_split_prints_and_writes_one_process_per_robot(fame_models, tmp_path, capsys):
    agri = fame_models / "fame-ros" / "agri.bpmn"
    code = main(
        [
            "fame",
            "split",
            str(agri),
            "--robots",
            "drone,tractor_1,tractor_2",
            "--out",
            str(tmp_path),
        ]
    )
    out = capsys.readouterr().out
    assert code == 0
    assert out.splitlines()[:3] == [
        "tractor_1\tTractor\tProcess_169rpm3",
        "tractor_2\tTractor\tProcess_169rpm3",
        "drone\tDrone\tdrone_process",
    ]
    assert sorted(p.name for p in tmp_path.iterdir()) == [
        "drone.bpmn",
        "tractor_1.bpmn",
        "tractor_2.bpmn",
    ]
    drone = parse(tmp_path / "drone.bpmn")
    assert [(pool.name, process.id) for pool, process in drone.pools()] == [
        ("Drone", "drone_process")
    ]
    original = parse(agri).processes["drone_process"]
    assert [n.id for n in drone.processes["drone_process"].walk()] == [
        n.id for n in original.walk()
    ]


def test_split_of_an_unknown_robot_is_one_sentence(fame_models, capsys):
    agri = fame_models / "fame-ros" / "agri.bpmn"
    assert main(["fame", "split", str(agri), "--robots", "drone,rover_1"]) == 1
    err = capsys.readouterr().err
    assert err == f"robotale: {agri}: robot rover_1 matches no pool (pools: Tractor_<n>, Drone)\n"


def test_run_prints_every_tag_with_skills_from_a_file(models, capsys):
    code = main(
        [
            "fame",
            "run",
            str(models / "calls.bpmn"),
            "--library",
            str(models / "library"),
            "--skills",
            str(models / "library" / "rover_skills.py"),
            "--set",
            "rover.home_y=0",
            "--set",
            "rover.top_speed=2.5",
            # the skill reports its arrival as clock time; the model expects 5.0
            "--start",
            "1970-01-01T00:00:00Z",
        ]
    )
    captured = capsys.readouterr()
    assert code == 0, captured.err
    lines = captured.out.splitlines()
    assert lines[0].split("\t") == ["     0.000", "rover", "blink", "start"]
    assert lines[-1].split("\t") == ["     5.000", "rover", "celebrate", "complete"]
    assert "# done at 5.000 s; instances completed: rover 1" in captured.err


def test_run_reports_uncaught_errors_with_exit_status_1(models, capsys):
    code = main(
        [
            "fame",
            "run",
            str(models / "errors.bpmn"),
            "--robots",
            "tractor_1",
            "--set",
            "tractor_1.jammed=false",
            "--set",
            'tractor_1.fail_loudly="overheat"',
        ]
    )
    assert code == 1
    assert (
        "error 'overheat' thrown at check (Check Blade) was not caught" in capsys.readouterr().err
    )


@pytest.mark.parametrize("bad", ["delay=10", "drone.=1", "drone.delay"])
def test_run_rejects_malformed_variables(models, capsys, bad):
    assert main(["fame", "run", str(models / "event_race.bpmn"), "--set", bad]) == 1
    assert "is not ROBOT.NAME=VALUE" in capsys.readouterr().err


def test_run_imports_a_skills_module_from_the_current_folder(models, capsys, monkeypatch):
    monkeypatch.chdir(models / "library")
    monkeypatch.setattr(sys, "path", list(sys.path))  # the folder joins the path for this test
    code = main(
        [
            "fame",
            "run",
            "../calls.bpmn",
            "--library",
            ".",
            "--skills",
            "rover_skills",
            "--set",
            "rover.home_y=0",
            "--set",
            "rover.top_speed=2.5",
            # the skill reports its arrival as clock time; the model expects 5.0
            "--start",
            "1970-01-01T00:00:00Z",
        ]
    )
    assert code == 0 and capsys.readouterr().out.splitlines()[-1].endswith("celebrate\tcomplete")


def test_a_skills_module_without_skills_is_one_sentence(models, tmp_path, capsys):
    empty = tmp_path / "empty_skills.py"
    empty.write_text("NOTHING = 1\n")
    assert main(["fame", "run", str(models / "calls.bpmn"), "--skills", str(empty)]) == 1
    assert capsys.readouterr().err == (
        f"robotale: the skills module {str(empty)!r} has no SKILLS mapping of name to skill\n"
    )


@pytest.mark.parametrize("command", ["fame run", "fame node", "record"])
def test_dds_commands_without_cyclone_dds_say_so_in_one_sentence(
    command, models, tmp_path, monkeypatch, capsys
):
    # the package cannot be uninstalled from the shared environment: hide it from imports
    monkeypatch.setitem(sys.modules, "cyclonedds.core", None)
    bag, model = tmp_path / "bag", str(models / "hello_at_once.bpmn")
    arguments = {
        "fame run": ["fame", "run", model, "--bus", "dds", "--record", str(bag)],
        "fame node": ["fame", "node", model, "--robot", "caller"],
        "record": ["record", str(bag), "--robots", "caller"],
    }[command]
    assert main(arguments) == 1
    assert capsys.readouterr().err == (
        "robotale: one process per robot (--bus dds, fame node, record) needs Cyclone DDS: "
        "pip install 'robotale[dds]'\n"
    )
    assert not bag.exists()
