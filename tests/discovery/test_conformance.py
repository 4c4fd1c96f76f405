import pandas as pd
import pm4py
import pytest

from robotale.discovery.conformance import RobotModel, replay
from robotale.eventlog.schema import ACTIVITY, CASE, ROBOT

T0 = pd.Timestamp("2024-01-01T10:00:00+00:00")


def traces_of(robot: str, runs: dict[str, list[str]]) -> pd.DataFrame:
    rows = [
        (case, robot, activity, T0 + pd.Timedelta(seconds=i))
        for case, activities in runs.items()
        for i, activity in enumerate(activities)
    ]
    return pd.DataFrame(rows, columns=[CASE, ROBOT, ACTIVITY, "start_timestamp"])


@pytest.fixture(scope="module")
def survey_model() -> RobotModel:
    tree = pm4py.parse_process_tree("->('take_off', *('survey', τ), 'report', X('land', 'crash'))")
    return RobotModel("Drone", *pm4py.convert_to_petri_net(tree))


def test_runs_played_out_from_the_model_fit(survey_model):
    played = pm4py.play_out(*survey_model[1:], parameters={"noTraces": 20})
    runs = {str(i): [event["concept:name"] for event in trace] for i, trace in enumerate(played)}
    report = replay(traces_of("drone", runs), {"drone": survey_model})
    assert report.summary["fitting"] and report.summary["fitness"] == 1.0
    assert report.robots.iloc[0][["robot", "pool", "runs", "fitting_runs"]].tolist() == [
        "drone",
        "Drone",
        20,
        20,
    ]
    assert report.deviations.empty


def test_missing_and_swapped_activities_are_named(survey_model):
    runs = {
        "good": ["take_off", "survey", "report", "land"],
        "missing": ["take_off", "survey", "land"],
        "swapped": ["survey", "take_off", "report", "land"],
    }
    report = replay(traces_of("drone", runs), {"drone": survey_model})
    by_case = report.runs.set_index("case")
    assert by_case.loc["good", "fitness"] == 1.0 and by_case.loc["good", "fits"]
    assert (
        by_case.loc["missing", "fitness"] < 1
        and "missing report" in by_case.loc["missing", "deviations"]
    )
    assert by_case.loc["swapped", "fitness"] < 1
    assert {"survey", "take_off"} & {
        activity for activity in report.deviations["activity"] if activity != "report"
    }
    assert report.summary["fitness"] < 1 and not report.summary["fitting"]
    assert report.to_dict()["deviations"][0]["robot"] == "drone"
