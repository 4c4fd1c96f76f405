"""Batches: runs spread over worker processes, each one bag; a crashed run is reported and
does not stop the batch; nothing is left half-written."""

from __future__ import annotations

import json
import time
from pathlib import Path

import pytest
from simbags import manifest, record

from robotale.cli import main
from robotale.errors import InputError
from robotale.sim.batch import SUMMARY, run_into, simulate_batch
from robotale.sim.plans import plans
from robotale.sim.worldspec import load_world

ROVER = """<?xml version="1.0" encoding="UTF-8"?>
<bpmn:definitions xmlns:bpmn="http://www.omg.org/spec/BPMN/20100524/MODEL" id="d">
  <bpmn:process id="Rover" name="Rover" isExecutable="true">
    <bpmn:startEvent id="start" />
    <bpmn:callActivity id="where" name="Get Position" calledElement="GetPosition" />
    <bpmn:scriptTask id="check" name="Check" scriptFormat="python">
      <bpmn:script>
if my_x &gt; 0:
    {action}
      </bpmn:script>
    </bpmn:scriptTask>
    <bpmn:endEvent id="end" />
    <bpmn:sequenceFlow id="f1" sourceRef="start" targetRef="where" />
    <bpmn:sequenceFlow id="f2" sourceRef="where" targetRef="check" />
    <bpmn:sequenceFlow id="f3" sourceRef="check" targetRef="end" />
  </bpmn:process>
</bpmn:definitions>
"""

WORLD = """model: rover.bpmn
field: [4, 4]
time_limit: 30
bases:
  home: {position: [0, 0]}
robots:
  rover: {kind: ground, base: home, start_jitter: 0.3}
"""


def rover_world(folder: Path, action: str):
    """A rover that checks where it started, and ``action`` when east of its base."""
    folder.mkdir(parents=True, exist_ok=True)
    (folder / "rover.bpmn").write_text(ROVER.format(action=action), encoding="utf-8")
    (folder / "rover.yaml").write_text(WORLD, encoding="utf-8")
    return load_world(folder / "rover.yaml")


def east(run: dict) -> bool:
    return run["setup"]["robots"]["rover"]["x"] > 0


def test_a_run_that_raises_is_reported_crashed_and_the_batch_goes_on(tmp_path):
    world = rover_world(tmp_path / "model", 'raise RuntimeError("started east of its base")')
    out = tmp_path / "runs"
    summary = simulate_batch(plans(world, "rover", runs=6, seed=5), out, workers=0)
    runs = [manifest(out / f"run_{i:04d}") for i in range(1, 7)]
    crashed = [r for r in runs if r["outcome"]["status"] == "crashed"]
    ended = [r for r in runs if r["outcome"]["status"] == "ended"]
    assert crashed and ended  # the seed gives both kinds
    assert all(east(r) for r in crashed) and not any(east(r) for r in ended)
    reason = crashed[0]["outcome"]["reason"]
    assert reason == (
        "ModelError: robot rover: script task check (Check) failed: RuntimeError: "
        "started east of its base"
    )
    assert all((out / r["case"] / "metadata.yaml").is_file() for r in runs)  # bags closed
    assert summary["outcomes"] == {"crashed": len(crashed), "ended": len(ended)}
    assert json.loads((out / SUMMARY).read_text())["cases"][0]["case"] == "run_0001"
    assert not list(out.glob(".*"))


@pytest.mark.slow
def test_a_run_that_kills_its_worker_process_is_reported_and_the_others_finish(tmp_path):
    world = rover_world(tmp_path / "model", "import os; os._exit(3)")
    out = tmp_path / "runs"
    summary = simulate_batch(plans(world, "rover", runs=4, seed=5), out, workers=2)
    runs = {f"run_{i:04d}": manifest(out / f"run_{i:04d}") for i in range(1, 5)}
    died = {c for c, r in runs.items() if r["outcome"]["status"] == "crashed"}
    assert died and len(died) < 4
    for case, run in runs.items():
        if case in died:
            assert "worker process running it died" in run["outcome"]["reason"]
            assert not (out / case / "metadata.yaml").exists()
        else:
            assert run["outcome"]["status"] == "ended"
            assert (out / case / "metadata.yaml").is_file()
    assert summary["outcomes"]["crashed"] == len(died)
    assert not list(out.glob(".*"))


def test_earlier_runs_are_kept_unless_overwrite_is_given(tmp_path):
    world = rover_world(tmp_path / "model", "pass")
    out = tmp_path / "runs"
    simulate_batch(plans(world, "rover", runs=1, seed=1), out, workers=0)
    with pytest.raises(InputError, match=r"already holds recorded runs \(run_0001 \.\.\.\)"):
        simulate_batch(plans(world, "rover", runs=1, seed=2), out, workers=0)
    assert manifest(out / "run_0001")["batch_seed"] == 1
    simulate_batch(plans(world, "rover", runs=1, seed=2), out, workers=0, overwrite=True)
    assert manifest(out / "run_0001")["batch_seed"] == 2


def test_the_command_simulates_a_batch_and_reports_it(tmp_path, capsys):
    out = tmp_path / "agri"
    status = main(
        [
            "simulate",
            "agri",
            "--runs",
            "2",
            "--tractors",
            "3",
            "--weeds",
            "2",
            "--seed",
            "4",
            "--out",
            str(out),
            "--workers",
            "2",
        ]
    )
    captured = capsys.readouterr()
    assert status == 0
    assert captured.out.startswith("2 runs of agri in ")
    assert "simulate" in captured.err  # the progress bar
    runs = sorted(p.name for p in out.iterdir())
    assert runs == ["robotale-batch.json", "run_0001", "run_0002"]
    first = manifest(out / "run_0001")
    assert set(first["robots"]) == {"drone", "tractor_1", "tractor_2", "tractor_3"}
    assert first["weeds"]["total"] == 2
    assert first["settings"]["tractors"] == 3


@pytest.mark.parametrize(
    ("arguments", "message"),
    [
        (["farm"], "there is no scenario 'farm'; the scenarios are agri, rexdingo"),
        (["agri", "--tractors", "11"], "pool Tractor allows at most 10 robots, 11 given"),
        (["agri", "--fault", "die:tractor_7@5"], "there is no robot 'tractor_7'"),
        (["agri", "--weeds", "many"], "--weeds 'many' must be a number or LOW-HIGH"),
        (["rexdingo", "--weeds", "2"], "this world has no weeds to count"),
        (["agri", "--gui"], "--gui needs a display"),
        (["agri", "--runs", "0"], "--runs 0: give the number of runs to simulate, 1 or more."),
        (["agri", "--runs", "-2"], "--runs -2: give the number of runs to simulate, 1 or more."),
    ],
)
def test_mistakes_are_one_sentence_and_write_nothing(
    tmp_path, capsys, monkeypatch, arguments, message
):
    monkeypatch.delenv("DISPLAY", raising=False)
    monkeypatch.delenv("WAYLAND_DISPLAY", raising=False)
    out = tmp_path / "runs"
    assert main(["simulate", *arguments, "--out", str(out)]) == 1
    error = capsys.readouterr().err
    assert error.startswith("robotale: ") and message in error
    assert len(error.strip().splitlines()) == 1
    assert not out.exists()


def test_a_batch_with_crashed_runs_exits_non_zero_naming_them(tmp_path, capsys):
    folder = tmp_path / "mine"
    rover_world(folder, "undefined_name")  # a NameError when the rover starts east
    out = tmp_path / "runs"
    arguments = ["simulate", "--world", str(folder / "rover.yaml"), "--runs", "6", "--seed", "5"]
    assert main([*arguments, "--out", str(out), "--quiet", "--workers", "0"]) == 1
    runs = [manifest(out / f"run_{i:04d}") for i in range(1, 7)]
    crashed = [r for r in runs if r["outcome"]["status"] == "crashed"]
    assert crashed and len(crashed) < 6  # the seed gives both kinds; the good runs are kept
    error = capsys.readouterr().err.strip()
    which = "; ".join(f"{r['case']}: {r['outcome']['reason']}" for r in crashed)
    assert error == f"robotale: {len(crashed)} of 6 run(s) crashed ({which})."
    assert "NameError" in crashed[0]["outcome"]["reason"]


def test_a_full_disk_is_one_sentence_and_keeps_only_whole_runs(small_disk, capsys):
    out = small_disk("300k") / "runs"  # one rexdingo run (about 190 KB) fits, two do not
    arguments = ["simulate", "rexdingo", "--runs", "2", "--quiet", "--workers", "0"]
    assert main([*arguments, "--out", str(out)]) == 1
    error = capsys.readouterr().err.strip()
    assert error.startswith(f"robotale: The disk of {out} is full: 2 runs need about ")
    assert error.endswith(
        "and only 1 fitted; they are kept whole, the run that did not fit was removed."
    )
    assert sorted(p.name for p in out.iterdir()) == ["run_0001"]  # no hidden partial run
    assert manifest(out / "run_0001")["outcome"]["status"] == "ended"
    assert (out / "run_0001" / "metadata.yaml").is_file()


def test_pace_slows_a_run_down_to_the_wall_clock_for_a_person_watching(tmp_path, capsys):
    out = tmp_path / "watched"
    began = time.perf_counter()
    assert main(["simulate", "rexdingo", "--pace", "200", "--out", str(out)]) == 0
    wall = time.perf_counter() - began
    assert capsys.readouterr().out.startswith("1 run of rexdingo in ")
    duration = manifest(out / "run_0001")["duration"]
    assert wall >= duration / 200


def test_a_model_and_world_of_ones_own_run_from_the_command_line(tmp_path, capsys):
    folder = tmp_path / "mine"
    rover_world(folder, "pass")
    out = tmp_path / "runs"
    arguments = ["simulate", "--world", str(folder / "rover.yaml"), "--runs", "3"]
    assert main([*arguments, "--out", str(out), "--quiet", "--workers", "0"]) == 0
    assert capsys.readouterr().out.startswith("3 runs of rover in ")
    assert all(manifest(out / f"run_{i:04d}")["outcome"]["status"] == "ended" for i in (1, 2, 3))
    broken = folder / "broken.bpmn"
    broken.write_text(ROVER.format(action="pass").replace("GetPosition", "Teleport"))
    assert main([*arguments, "--model", str(broken), "--out", str(tmp_path / "other")]) == 1
    error = capsys.readouterr().err
    assert "where (Get Position)" in error and "Teleport" in error
    assert not (tmp_path / "other").exists()


def test_manifests_name_shipped_scenarios_the_same_on_every_machine(short_agri, tmp_path):
    bag = record(short_agri, tmp_path / "runs")
    written = manifest(bag)
    assert written["model"] == "robotale/sim/scenarios/agri.bpmn"
    assert written["world"] == "robotale/sim/scenarios/agri.yaml"


def test_a_run_attempted_again_after_it_finished_keeps_the_first_bag(tmp_path):
    # A Dask cluster reruns a finished task when the worker holding its result dies, possibly
    # after the batch has moved on; the second attempt must leave the folder as it was.
    world = rover_world(tmp_path / "model", "pass")
    (plan,) = plans(world, "rover", runs=1, seed=5)
    out = tmp_path / "runs"
    out.mkdir()
    first = run_into(plan, out)
    before = {p: (p.stat().st_mtime_ns, p.read_bytes()) for p in (out / plan.case).iterdir()}
    assert run_into(plan, out) == json.loads(json.dumps(first))  # as the manifest file has it
    after = {p: (p.stat().st_mtime_ns, p.read_bytes()) for p in (out / plan.case).iterdir()}
    assert after == before
    assert sorted(p.name for p in out.iterdir()) == [plan.case]
