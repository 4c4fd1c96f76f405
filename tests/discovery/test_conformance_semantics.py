"""Every pattern of the engine's semantics suite, run by the engine, replays with fitness 1:
the Petri nets conformance builds allow exactly what the engine did."""

from pathlib import Path

import pytest

from robotale.discovery.conformance import check_conformance

SUITE = Path(__file__).resolve().parents[1] / "fame_runtime" / "models"


def navigate(robot, inputs, done):
    distance = abs(inputs["x_goal"]) + abs(inputs["y_goal"]) - 2.0
    timer = robot.clock.call_later(
        distance / inputs["speed"], lambda: done({"arrival": robot.now(), "distance": distance})
    )
    return timer.cancel


def drive(robot, inputs, done):
    return robot.clock.call_later(robot.variables["drive_time"], lambda: done({})).cancel


def tractors(**first):
    base = {"jammed": False, "fail_loudly": ""}
    return {"tractor_1": {**base, **first}, "tractor_2": dict(base)}


RUNS = {
    "sequence": ("sequence.bpmn", {"variables": {"rover": {"offset": 1}}}),
    "parallel": ("parallel.bpmn", {}),
    "signals": ("signals.bpmn", {"robots": ["drone", "tractor_1", "tractor_2"], "latency": 0.5}),
    "calls": (
        "calls.bpmn",
        {"skills": {"navigate": navigate}, "variables": {"rover": {"home_y": 0, "top_speed": 2.5}}},
    ),
    "terminate": ("terminate.bpmn", {}),
    "race, signal wins": ("event_race.bpmn", {"variables": {"drone": {"delay": 10}}}),
    "race, timer wins": ("event_race.bpmn", {"variables": {"drone": {"delay": 40}}}),
    "non-interrupting event sub-process": (
        "event_subprocesses.bpmn",
        {"variables": {"rover": {"reports": 0}, "operator": {"abort": False}}},
    ),
    "interrupting event sub-process": (
        "event_subprocesses.bpmn",
        {"variables": {"rover": {"reports": 0}, "operator": {"abort": True}}},
    ),
    "timer cycle event sub-process": ("timer_conditional_esp.bpmn", {}),
    "interrupting boundary timer": (
        "boundary.bpmn",
        {"skills": {"drive": drive}, "variables": {"rover": {"drive_time": 20, "beats": 0}}},
    ),
    "boundary events disarmed": (
        "boundary.bpmn",
        {"skills": {"drive": drive}, "variables": {"rover": {"drive_time": 2.5, "beats": 0}}},
    ),
    "sub-process": ("errors.bpmn", {"robots": ["tractor_1", "tractor_2"], "variables": tractors()}),
    "error end caught": (
        "errors.bpmn",
        {"robots": ["tractor_1", "tractor_2"], "variables": tractors(jammed=True)},
    ),
    "script error caught": (
        "errors.bpmn",
        {"robots": ["tractor_1"], "variables": tractors(fail_loudly="blade_jammed")},
    ),
    # a multi-instance activity over a collection, by a cardinality read from a variable,
    # cut short by its completion condition; standard loops tested after, before, capped
    "loops": (
        "loops.bpmn",
        {
            "variables": {
                "rover": {"fields": ["a", "b", "c"], "blinks": 3, "depths": [5, 20, 35, 50]}
                | {"steps": 0, "tries": 0}
            }
        },
    ),
    "inclusive, two branches": (
        "inclusive.bpmn",
        {"variables": {"rover": {"jobs": ["clean", "photo"]}}},
    ),
    "inclusive, three branches": (
        "inclusive.bpmn",
        {"variables": {"rover": {"jobs": ["clean", "water", "photo"]}}},
    ),
}


@pytest.mark.parametrize("name", list(RUNS))
def test_what_the_engine_did_fits_the_model(name, engine_log):
    model, options = RUNS[name]
    log = engine_log(SUITE / model, library=SUITE / "library", **options)
    report = check_conformance(log, SUITE / model, library=SUITE / "library")
    assert report.deviations.empty, report.runs["deviations"].tolist()
    assert report.summary["fitness"] == 1.0
    assert set(report.runs["method"]) == {"alignment"}
