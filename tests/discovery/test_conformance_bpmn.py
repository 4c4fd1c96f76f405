"""Conformance against BPMN collaborations, with logs the engine itself produced."""

from pathlib import Path

import pandas as pd
import pytest

from robotale.discovery.bpmn_net import process_net
from robotale.discovery.conformance import check_conformance
from robotale.errors import InputError
from robotale.eventlog.schema import ACTIVITY, CASE, ROBOT
from robotale.fame_runtime.library import Library, find_process
from robotale.fame_runtime.parser import parse

MODEL = Path(__file__).parent / "models" / "scout_workers.bpmn"


@pytest.fixture(scope="module")
def runs(engine_log) -> pd.DataFrame:
    """Three runs taking different paths: two finds with two workers, three finds with one,
    and one find with no worker at all, so the scout gives up waiting (its timer fires)."""
    teams = {"1": ["scout", "worker_1", "worker_2"], "2": ["scout", "worker_1"], "3": ["scout"]}
    planned = {"1": 2, "2": 3, "3": 1}
    return pd.concat(
        [
            engine_log(MODEL, case, robots=robots, variables={"scout": {"planned": planned[case]}})
            for case, robots in teams.items()
        ],
        ignore_index=True,
    )


def test_runs_the_engine_produced_fit_the_model(runs):
    assert "give_up" in set(runs[ACTIVITY])  # the timer path was taken
    report = check_conformance(runs, MODEL)
    assert report.summary["fitting"] and report.summary["fitness"] == 1.0
    robots = report.robots.set_index("robot")
    assert robots.loc["scout", "pool"] == "Scout" and robots.loc["scout", "runs"] == 3
    assert robots.loc["worker_1", "pool"] == "Worker" and robots.loc["worker_1", "runs"] == 2
    assert set(report.runs["method"]) == {"alignment"}
    assert report.deviations.empty


def test_a_missing_activity_is_named(runs):
    treat = runs.index[
        (runs[CASE] == "2") & (runs[ROBOT] == "worker_1") & (runs[ACTIVITY] == "treat")
    ]
    report = check_conformance(runs.drop(treat[:2]), MODEL)  # the first treatment's two tags
    run = report.runs.set_index(["case", "robot"]).loc[("2", "worker_1")]
    assert run["fitness"] < 1 and run["deviations"] == "missing treat"
    assert report.deviations.to_dict("records") == [
        {"robot": "worker_1", "activity": "treat", "kind": "missing", "count": 1, "runs": 1}
    ]
    others = report.runs[(report.runs["case"] != "2") | (report.runs["robot"] != "worker_1")]
    assert others["fits"].all()


def test_swapped_activities_are_named(runs):
    scout = runs[(runs[CASE] == "1") & (runs[ROBOT] == "scout")]
    first_two = scout[scout[ACTIVITY].isin(["take_off", "survey"])].index[:4]
    # every tag carries the same simulated time, so the order of the rows is the order of events
    order = list(runs.index)
    take_off, survey = list(first_two[:2]), list(first_two[2:])
    position = order.index(take_off[0])
    order[position : position + 4] = survey + take_off
    swapped = runs.loc[order].reset_index(drop=True)
    report = check_conformance(swapped, MODEL)
    run = report.runs.set_index(["case", "robot"]).loc[("1", "scout")]
    assert run["fitness"] < 1
    assert {"take_off", "survey"} & set(report.deviations["activity"])
    assert report.summary["fitness"] < 1


def test_pools_that_do_not_match_the_robots_are_refused(runs):
    strangers = runs.assign(**{ROBOT: runs[ROBOT].replace({"scout": "drone"})})
    with pytest.raises(InputError, match=r"drone.*matches no pool.*Scout.*robots are drone"):
        check_conformance(strangers, MODEL)


def test_every_thesis_model_becomes_a_net(fame_models):
    library = Library(fame_models / "fame-ros")
    for path in sorted(fame_models.rglob("*.bpmn")):
        definitions = parse(path)
        for pool, process in definitions.pools():

            def resolve(name, definitions=definitions):
                return find_process(definitions, name) or library.find(name)

            net, _, _ = process_net(process, set(), resolve)
            assert net.transitions, f"{path.name}: pool {pool.name} has no transition"


def test_agricultural_pools_carry_the_message_labels(fame_models):
    definitions = parse(fame_models / "fame-ros" / "agri.bpmn")
    library = Library(fame_models / "fame-ros")
    labels = {}
    for pool, process in definitions.pools():
        net, _, _ = process_net(process, set(), library.find)
        labels[pool.name] = {t.label for t in net.transitions if t.label}
    assert {"weed_position!", "tractor_position?", "closest_tractor!", "weed_found?"} <= labels[
        "Drone"
    ]
    assert {"weed_position?", "tractor_position!", "closest_tractor?", "cut_grass"} <= labels[
        "Tractor"
    ]


def test_the_thesis_log_against_the_thesis_model(thesis_log, fame_models):
    # the authors tagged their ROS code by hand (move, cut_grass ...), so their log and their
    # model disagree in places; the drone's single long run (thousands of events) takes the
    # token-replay fallback, while a tractor's alignment needs well under the budget even on
    # a busy machine (1 s was too tight under load)
    folder = fame_models / "fame-ros"
    report = check_conformance(
        thesis_log, folder / "agri.bpmn", library=folder, seconds_per_trace=8
    )
    robots = report.robots.set_index("robot")
    assert robots.loc["drone", "method"] == "token replay"
    assert robots.loc["tractor_1", "method"] == "alignment"
    assert all(0 < f < 1 for f in robots["fitness"])
    assert ("tractor_1", "move", "unexpected") in {
        (d["robot"], d["activity"], d["kind"]) for d in report.deviations.to_dict("records")
    }
    # select_closest_tractor carries msg_role send, and no element of the model sends it
    assert report.outside.to_dict("records") == [
        {"robot": "drone", "activity": "select_closest_tractor", "instances": 108}
    ]


NO_END = """<bpmn:definitions xmlns:bpmn="http://www.omg.org/spec/BPMN/20100524/MODEL" id="unsound">
  <bpmn:collaboration id="collab">
    <bpmn:participant id="p" name="Rover" processRef="Rover" />
  </bpmn:collaboration>
  <bpmn:process id="Rover">
    <bpmn:startEvent id="start" />
    <bpmn:exclusiveGateway id="split" />
    <bpmn:task id="a" name="a" />
    <bpmn:task id="b" name="b" />
    <bpmn:parallelGateway id="merge" />
    <bpmn:task id="c" name="c" />
    <bpmn:endEvent id="end" />
    <bpmn:sequenceFlow id="f1" sourceRef="start" targetRef="split" />
    <bpmn:sequenceFlow id="f2" sourceRef="split" targetRef="a" />
    <bpmn:sequenceFlow id="f3" sourceRef="split" targetRef="b" />
    <bpmn:sequenceFlow id="f4" sourceRef="a" targetRef="merge" />
    <bpmn:sequenceFlow id="f5" sourceRef="b" targetRef="merge" />
    <bpmn:sequenceFlow id="f6" sourceRef="merge" targetRef="c" />
    <bpmn:sequenceFlow id="f7" sourceRef="c" targetRef="end" />
  </bpmn:process>
</bpmn:definitions>"""


def test_a_pool_whose_end_cannot_be_reached_is_one_sentence(tmp_path, capsys):
    """An exclusive split into a parallel join: no run can complete, so nothing can be
    aligned (pm4py would raise its own exception)."""
    from robotale.cli import main

    model = tmp_path / "no_end.bpmn"
    model.write_text(NO_END)
    log = tmp_path / "rover.csv"
    log.write_text(
        "case,time,activity,lifecycle,robot\n"
        "1,2024-01-01T10:00:00Z,a,start,rover\n1,2024-01-01T10:00:01Z,a,complete,rover\n"
        "1,2024-01-01T10:00:02Z,c,start,rover\n1,2024-01-01T10:00:03Z,c,complete,rover\n"
    )
    assert main(["discover", "conformance", str(log), "--model", str(model)]) == 1
    err = capsys.readouterr().err.strip().splitlines()[-1]
    assert err.startswith(f"robotale: {model}: no run of pool Rover can reach its end event")
