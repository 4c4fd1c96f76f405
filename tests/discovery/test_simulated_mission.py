"""The loop closed on robotale's own simulated agricultural mission: the robots run the BPMN
collaboration in pybullet, the bags become an event log, and every robot's runs conform to its
pool of that same collaboration."""

import json
from importlib.resources import files

import pytest

from robotale.cli import main
from robotale.discovery import LogFilter, check_conformance, discover_dfg
from robotale.enhancement import all_perspectives
from robotale.eventlog.readers import read_log

pytestmark = [
    pytest.mark.slow,
    pytest.mark.filterwarnings("ignore:Install the optional requirement:UserWarning"),
]
AGRI = files("robotale.sim.scenarios") / "agri.bpmn"


@pytest.fixture(scope="module")
def agri_csv(tmp_path_factory):
    folder = tmp_path_factory.mktemp("agri")
    runs, csv = folder / "runs", folder / "agri.csv"
    assert main(["simulate", "agri", "--runs", "2", "--tractors", "2", "--seed", "1",
                 "--out", str(runs), "--quiet"]) == 0  # fmt: skip
    assert main(["prepare", str(runs), "--out", str(csv)]) == 0
    return csv


def test_every_robot_conforms_to_the_collaboration_that_drove_it(agri_csv):
    report = check_conformance(read_log(agri_csv), AGRI)
    assert report.summary["fitness"] == 1.0 and report.deviations.empty
    assert set(report.robots["pool"]) == {"Drone", "Tractor"}
    assert report.robots.set_index("robot").loc["drone", "runs"] == 2
    # the explore skill publishes weed_found itself and consumes closest_tractor itself (its
    # resume_on): the process models neither, and each is tagged as the skill sent or received it
    outside = report.outside.set_index("activity")["instances"].to_dict()
    assert set(report.outside["robot"]) == {"drone"}
    assert set(outside) == {"weed_found!", "closest_tractor?"}
    log = read_log(agri_csv)
    ends = log[(log["robot"] == "drone") & (log["lifecycle:transition"] != "start")]
    for activity, instances in outside.items():  # an instance per send or receive: its end
        assert instances == ends["concept:name"].eq(activity).sum() > 0


def test_a_run_missing_an_activity_is_caught(agri_csv):
    log = read_log(agri_csv)
    cuts = log[(log["robot"] == "tractor_1") & (log["concept:name"] == "cut_grass")]
    first = cuts[cuts["case:concept:name"] == cuts["case:concept:name"].iloc[0]]
    done = first.loc[first["lifecycle:transition"] == "complete", "time:timestamp"].iloc[0]
    without = log.drop(first.index[first["time:timestamp"] <= done])  # its first cut, all of it
    report = check_conformance(without, AGRI)
    assert report.summary["fitness"] < 1
    assert ("tractor_1", "cut_grass", "missing") in {
        (d["robot"], d["activity"], d["kind"]) for d in report.deviations.to_dict("records")
    }


def test_perspectives_and_dfg_of_the_simulated_mission(agri_csv, tmp_path):
    log = read_log(agri_csv)
    results = all_perspectives(log)
    assert all(p.has_data for name, p in results.items() if name != "bottlenecks")
    battery = results["battery"].tables["consumption"].set_index(["activity", "robot"])
    assert battery.loc[("explore", "drone"), "used"] > 0  # flying drains the drone
    assert results["communication"].summary["lost"] == 0
    drone = discover_dfg(log, LogFilter(robots=["drone"]))
    assert ("__start__", "take_off") in drone.edge_counts()
    assert ("take_off", "explore") in drone.edge_counts()
    out = tmp_path / "report.json"
    assert main(["perspectives", str(agri_csv), "--json", str(out)]) == 0
    assert json.loads(out.read_text())["spatial"]["summary"]["positions"] == len(log)
