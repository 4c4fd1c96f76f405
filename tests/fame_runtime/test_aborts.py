"""An activity that does not complete ends with an ``ate_abort`` tag (XES' transition for an
aborted activity): interrupted by a boundary event or an event sub-process, or cancelled by
an uncaught error or a stop. The expected traces are the token semantics' (test_semantics.py)
with the aborts where the tokens were cut."""

from __future__ import annotations

from fame_suite import build, pair, run, trace
from test_semantics import Drive, Patrol, safe_state, tractors

from robotale.fame_runtime.engine import Engine


def test_an_interrupting_boundary_timer_ends_the_skill_with_ate_abort():
    _mission, tags = run(
        "boundary.bpmn",
        skills={"drive": Drive()},
        variables={"rover": {"drive_time": 20, "beats": 0}},
    )
    aborted = [t for t in trace(tags, aborts=True) if t[3] == "ate_abort"]
    assert aborted == [(5, "rover", "drive", "ate_abort")]
    after = trace(tags, aborts=True)[trace(tags, aborts=True).index(aborted[0]) + 1 :]
    assert after == [*pair(5, "rover", "too_slow"), *pair(5, "rover", "stop_driving")]


def test_an_uncaught_error_cancels_the_open_activities_innermost_first():
    _mission, tags = run(
        "errors.bpmn", robots=["tractor_1"], variables=tractors(fail_loudly="overheat")
    )
    assert trace(tags, aborts=True) == [
        (0, "tractor_1", "cut_grass", "start"),
        (0, "tractor_1", "check_blade", "start"),
        (0, "tractor_1", "check_blade", "ate_abort"),
        (0, "tractor_1", "cut_grass", "ate_abort"),
    ]


def test_a_stop_cancels_the_activity_before_the_safe_state_handler_runs():
    mission, tags = build("safe_state.bpmn", skills={"patrol": Patrol()})
    rover = mission.engines["rover"]
    mission.clock.call_at(3, rover.stop)
    mission.run()
    assert trace(tags, aborts=True) == [
        (0, "rover", "patrol", "start"),
        (3, "rover", "patrol", "ate_abort"),
        *safe_state(3),
    ]


def test_the_observer_is_told_how_each_instance_ended():
    """Apart from the tags, the engine tells an observer each instance's number and outcome
    (the simulator's ground truth): interrupted under a boundary event, else completed."""
    mission, _tags = build(
        "boundary.bpmn",
        skills={"drive": Drive()},
        variables={"rover": {"drive_time": 20, "beats": 0}},
    )
    seen = []
    engine: Engine = mission.engines["rover"]
    engine.activity_observer = lambda *event: seen.append(event)
    mission.run()
    drive = [e for e in seen if e[2] == "drive"]
    assert [e[3] for e in drive] == ["start", "interrupted"] and drive[0][1] == drive[1][1]
    assert {e[3] for e in seen if e[2] == "stop_driving"} == {"start", "completed"}
