"""The semantics suite beyond the core: event-based race, event sub-processes, boundary
events, errors, safe state, inclusive gateway, start events, conditional events. Each test
states the exact trace of tags the model must leave, worked out by hand from the model."""

from datetime import UTC, datetime

import pytest
from fame_suite import build, of, pair, run, trace

from robotale.errors import ModelError
from robotale.fame_runtime.parser import parse


@pytest.mark.parametrize("delay", [10, 40])
def test_event_based_gateway_race_of_signal_against_timer(delay):
    mission, tags = run("event_race.bpmn", variables={"drone": {"delay": delay}})
    drone = [*pair(delay, "drone", "think"), *pair(delay, "drone", "closest_tractor!")]
    if delay < 30:  # the signal wins; the 30 s timer is disarmed
        tractor = [*pair(10, "tractor", "closest_tractor?"), *pair(10, "tractor", "go")]
        assert trace(tags) == drone + tractor
        assert mission.engines["tractor"].variables["chosen"] == "tractor"
    else:  # the timer wins at 30 s; the signal at 40 s finds no token waiting
        tractor = [*pair(30, "tractor", "30_sec"), *pair(30, "tractor", "give_up")]
        assert trace(tags) == tractor + drone
    assert mission.clock.next_time() is None and mission.done


def handler(time, robot, name, trigger, *work):
    """An event sub-process run: its trigger caught, its start, its work, its completion."""
    inner = [t for activity in work for t in pair(time, robot, activity)]
    caught = pair(time, robot, trigger)
    return [*caught, (time, robot, name, "start"), *inner, (time, robot, name, "complete")]


def test_non_interrupting_event_sub_process_runs_each_time_alongside_the_work():
    variables = {"rover": {"reports": 0}, "operator": {"abort": False}}
    mission, tags = run("event_subprocesses.bpmn", variables=variables)
    assert of(tags, "rover") == [
        *pair(0, "rover", "begin"),
        *handler(2, "rover", "status_handler", "status?", "report"),
        *handler(4, "rover", "status_handler", "status?", "report"),
        *pair(10, "rover", "work_10_s"),
        *pair(10, "rover", "finish"),
    ]
    assert mission.engines["rover"].variables["reports"] == 2


def test_interrupting_event_sub_process_cancels_the_work():
    variables = {"rover": {"reports": 0}, "operator": {"abort": True}}
    mission, tags = run("event_subprocesses.bpmn", variables=variables)
    assert of(tags, "rover") == [
        *pair(0, "rover", "begin"),
        *handler(2, "rover", "status_handler", "status?", "report"),
        *handler(4, "rover", "status_handler", "status?", "report"),
        *handler(6, "rover", "abort_handler", "abort?", "abort_mission"),
    ]
    rover = mission.engines["rover"]
    assert rover.completed == 1 and rover.idle and mission.clock.now() == 6


def test_timer_cycle_event_sub_process_fires_three_times():
    mission, tags = run("timer_conditional_esp.bpmn")
    ticks = [t for time in (2, 4, 6) for t in handler(time, "rover", "ticker", "every_2_s", "tick")]
    assert trace(tags) == [*ticks, *pair(10, "rover", "work_10_s")]
    assert mission.engines["rover"].variables["ticks"] == 3


def test_conditional_event_sub_process_fires_when_a_variable_it_reads_changes():
    mission, tags = build("timer_conditional_esp.bpmn")
    rover = mission.engines["rover"]
    mission.clock.call_at(3, lambda: rover.set_variables(battery=50))  # still fine
    mission.clock.call_at(5, lambda: rover.set_variables(battery=10))
    mission.run()
    ticks = [t for time in (2, 4) for t in handler(time, "rover", "ticker", "every_2_s", "tick")]
    low = handler(5, "rover", "low_battery_handler", "battery_low", "go_home")
    assert trace(tags) == ticks + low  # the work and the remaining tick are cancelled
    assert rover.variables["ticks"] == 2 and mission.clock.next_time() is None


class Drive:
    """A skill that drives for ``drive_time`` simulated seconds and can be cancelled."""

    def __init__(self):
        self.cancelled = False

    def __call__(self, robot, inputs, done):
        timer = robot.clock.call_later(robot.variables["drive_time"], lambda: done({}))

        def cancel():
            self.cancelled = True
            timer.cancel()

        return cancel


def test_interrupting_boundary_timer_cancels_the_skill_and_cycle_beats_three_times():
    drive = Drive()
    mission, tags = run(
        "boundary.bpmn",
        skills={"drive": drive},
        variables={"rover": {"drive_time": 20, "beats": 0}},
    )
    beats = [
        t
        for time in (1, 2, 3)
        for t in pair(time, "rover", "heartbeat") + pair(time, "rover", "beat")
    ]
    assert trace(tags) == [
        (0, "rover", "drive", "start"),
        *beats,
        *pair(5, "rover", "too_slow"),
        *pair(5, "rover", "stop_driving"),
    ]
    assert drive.cancelled and mission.engines["rover"].variables["beats"] == 3


def test_boundary_events_are_disarmed_when_the_activity_completes():
    drive = Drive()
    mission, tags = run(
        "boundary.bpmn",
        skills={"drive": drive},
        variables={"rover": {"drive_time": 2.5, "beats": 0}},
    )
    beats = [
        t for time in (1, 2) for t in pair(time, "rover", "heartbeat") + pair(time, "rover", "beat")
    ]
    assert trace(tags) == [
        (0, "rover", "drive", "start"),
        *beats,
        (2.5, "rover", "drive", "complete"),
        *pair(2.5, "rover", "arrive"),
    ]
    assert not drive.cancelled and mission.clock.next_time() is None


def tractors(**first):
    base = {"jammed": False, "fail_loudly": ""}
    return {"tractor_1": {**base, **first}, "tractor_2": dict(base)}


def cut_ok(robot, start=0):
    return [
        (start, robot, "cut_grass", "start"),
        *pair(start, robot, "check_blade"),
        *pair(start + 3, robot, "cutting"),
        (start + 3, robot, "cut_grass", "complete"),
        *pair(start + 3, robot, "done"),
    ]


def test_sub_process_without_errors():
    _, tags = run("errors.bpmn", robots=["tractor_1", "tractor_2"], variables=tractors())
    assert of(tags, "tractor_1") == cut_ok("tractor_1") and of(tags, "tractor_2") == cut_ok(
        "tractor_2"
    )


def test_error_end_event_is_caught_by_the_boundary_event_of_its_sub_process():
    mission, tags = run(
        "errors.bpmn", robots=["tractor_1", "tractor_2"], variables=tractors(jammed=True)
    )
    assert of(tags, "tractor_1") == [
        (0, "tractor_1", "cut_grass", "start"),
        *pair(0, "tractor_1", "check_blade"),
        *pair(0, "tractor_1", "blade_jammed"),
        *pair(0, "tractor_1", "call_help"),
    ]
    assert of(tags, "tractor_2") == cut_ok("tractor_2")
    assert mission.clock.now() == 3 and not mission.failures


def test_bpmn_error_raised_by_a_script_is_caught_like_an_error_end_event():
    _, tags = run(
        "errors.bpmn", robots=["tractor_1"], variables=tractors(fail_loudly="blade_jammed")
    )
    assert of(tags, "tractor_1") == [
        (0, "tractor_1", "cut_grass", "start"),
        (0, "tractor_1", "check_blade", "start"),
        *pair(0, "tractor_1", "blade_jammed"),
        *pair(0, "tractor_1", "call_help"),
    ]


def test_error_topic_of_one_robot_triggers_its_error_event_sub_process_only():
    mission, tags = build("errors.bpmn", robots=["tractor_1", "tractor_2"], variables=tractors())
    bus, topics = mission.bus, []
    mission.clock.call_at(0.5, lambda: topics.extend(bus.topics()))
    mission.clock.call_at(
        1, lambda: bus.publish("/tractor_1/low_battery", {}, msgtype="std_msgs/msg/Empty")
    )
    mission.run()
    assert of(tags, "tractor_1") == [
        (0, "tractor_1", "cut_grass", "start"),
        *pair(0, "tractor_1", "check_blade"),
        *handler(1, "tractor_1", "battery_handler", "low_battery", "return_to_base"),
    ]
    assert of(tags, "tractor_2") == cut_ok("tractor_2")
    # Error events subscribe to the robot's own topic while they are armed.
    assert topics == [
        f"/{r}/{e}" for r in ("tractor_1", "tractor_2") for e in ("blade_jammed", "low_battery")
    ]
    assert bus.topics() == []  # every subscription went with the instances


def test_uncaught_error_ends_the_instance_and_is_reported():
    mission, tags = run(
        "errors.bpmn", robots=["tractor_1"], variables=tractors(fail_loudly="overheat")
    )
    assert of(tags, "tractor_1") == [
        (0, "tractor_1", "cut_grass", "start"),
        (0, "tractor_1", "check_blade", "start"),
    ]
    assert mission.failures == [
        "robot tractor_1: error 'overheat' thrown at check (Check Blade) was not caught; the "
        "process instance ended"
    ]
    assert mission.engines["tractor_1"].idle and mission.clock.next_time() is None


class Patrol:
    """A skill that patrols until cancelled."""

    def __init__(self):
        self.cancelled_at = None

    def __call__(self, robot, inputs, done):
        def cancel():
            self.cancelled_at = robot.now()

        return cancel


def safe_state(time):
    return [
        (time, "rover", "safe_state", "start"),
        *pair(time, "rover", "stop_motors"),
        *pair(time + 4, "rover", "drive_home"),
        *pair(time + 4, "rover", "park"),
        (time + 4, "rover", "safe_state", "complete"),
    ]


def test_terminate_gives_the_safe_state_handler_the_chance_to_run_first():
    patrol = Patrol()
    mission, tags = build("safe_state.bpmn", skills={"patrol": patrol})
    mission.clock.call_at(
        10,
        lambda: mission.bus.publish(
            "/mission_over", {}, msgtype="std_msgs/msg/Empty", sender="operator", msg_id="m_9"
        ),
    )
    mission.run()
    assert trace(tags, messages=True) == [
        (0, "rover", "patrol", "start", "", ""),
        (10, "rover", "mission_over?", "start", "m_9", "receive"),
        (10, "rover", "mission_over?", "complete", "m_9", "receive"),
        *[(*t, "", "") for t in safe_state(10)],
    ]
    assert patrol.cancelled_at == 10  # cancelled before the handler ran
    assert mission.engines["rover"].ended


def test_stop_runs_the_safe_state_handler():
    patrol = Patrol()
    mission, tags = build("safe_state.bpmn", skills={"patrol": patrol})
    rover = mission.engines["rover"]
    stopped = []
    mission.clock.call_at(3, lambda: rover.stop(then=lambda: stopped.append(rover.robot.now())))
    mission.run()
    assert trace(tags) == [(0, "rover", "patrol", "start"), *safe_state(3)]
    assert stopped == [7] and rover.ended and patrol.cancelled_at == 3


def test_replace_the_process_at_run_time_after_the_safe_state_handler(models):
    patrol = Patrol()
    mission, tags = build("safe_state.bpmn", skills={"patrol": patrol})
    new_process = parse(models / "parallel.bpmn").processes["Rover"]
    mission.clock.call_at(3, lambda: mission.replace("rover", new_process))
    mission.run()
    assert trace(tags) == [
        (0, "rover", "patrol", "start"),
        *safe_state(3),
        *pair(7, "rover", "b"),
        *pair(7, "rover", "c"),
        *pair(9, "rover", "wait_2_s"),
        *pair(9, "rover", "a"),
        *pair(9, "rover", "after_join"),
    ]
    assert mission.engines["rover"].completed == 2


def test_safe_state_handler_also_runs_on_its_own_trigger():
    mission, tags = build("safe_state.bpmn", skills={"patrol": Patrol()})
    mission.clock.call_at(
        2, lambda: mission.bus.publish("/rover/emergency", {}, msgtype="std_msgs/msg/Empty")
    )
    mission.run()
    assert trace(tags) == [
        (0, "rover", "patrol", "start"),
        *pair(2, "rover", "emergency"),  # caught, then the handler it triggers starts
        *safe_state(2),
    ]


@pytest.mark.parametrize(
    ("jobs", "expected"),
    [
        (
            ["clean", "photo"],
            [
                *pair(1, "rover", "1_s"),
                *pair(1, "rover", "clean"),
                *pair(3, "rover", "3_s"),
                *pair(3, "rover", "photo"),
                *pair(3, "rover", "report"),
            ],
        ),
        (["water"], [*pair(0, "rover", "water"), *pair(0, "rover", "report")]),
        (
            ["clean", "water", "photo"],
            [
                *pair(0, "rover", "water"),
                *pair(1, "rover", "1_s"),
                *pair(1, "rover", "clean"),
                *pair(3, "rover", "3_s"),
                *pair(3, "rover", "photo"),
                *pair(3, "rover", "report"),
            ],
        ),
    ],
)
def test_inclusive_join_waits_only_for_the_branches_taken(jobs, expected):
    _, tags = run("inclusive.bpmn", variables={"rover": {"jobs": jobs}})
    assert trace(tags) == expected


def test_inclusive_split_with_nothing_to_do_is_a_model_error():
    with pytest.raises(
        ModelError, match=r"inclusiveGateway split \(what to do\?\) has no outgoing flow"
    ):
        run("inclusive.bpmn", variables={"rover": {"jobs": []}})


def test_start_events_timer_cycle_date_condition_and_signal():
    epoch = datetime(2024, 1, 1, tzinfo=UTC).timestamp()
    mission, tags = build(
        "start_events.bpmn",
        start=epoch,
        variables={"watcher": {"level": 0}, "listener": {"pongs": []}},
    )
    watcher = mission.engines["watcher"]
    for delay, level in ((4, 3), (6, 7), (8, 9), (9, 1), (10, 8)):
        mission.clock.call_at(epoch + delay, lambda level=level: watcher.set_variables(level=level))
    mission.start()
    mission.clock.run(until=epoch + 20)
    at = lambda delay, robot, activity: pair(epoch + delay, robot, activity)  # noqa: E731
    assert of(tags, "ticker") == [
        t for d in (1, 2, 3) for t in at(d, "ticker", "every_second") + at(d, "ticker", "tick")
    ]
    assert of(tags, "alarm_clock") == [
        *at(10, "alarm_clock", "at_ten_past"),
        *at(10, "alarm_clock", "ring"),
    ]
    # level 7 at 6 s and 8 at 10 s make the condition become true; 9 at 8 s keeps it true.
    assert of(tags, "watcher") == [
        t for d in (6, 10) for t in at(d, "watcher", "level_high") + at(d, "watcher", "alarm")
    ]
    assert of(tags, "listener") == [
        t for d in (0, 5) for t in at(d, "listener", "ping?") + at(d, "listener", "pong")
    ]
    assert mission.engines["listener"].variables["pongs"] == [epoch, epoch + 5]
    assert mission.engines["listener"].completed == 2 and not mission.engines["listener"].ended
    assert mission.engines["ticker"].completed == 3


def test_conditional_catch_waits_for_a_variable_then_for_a_topic():
    mission, tags = build("conditional_catch.bpmn")
    rover, clock, bus = mission.engines["rover"], mission.clock, mission.bus

    def battery(level):
        return lambda: bus.publish(
            "/rover/battery", {"percentage": level}, msgtype="sensor_msgs/msg/BatteryState"
        )

    clock.call_at(1, battery(100))  # nobody reads the battery yet
    clock.call_at(2, lambda: rover.set_variables(docked=True))
    clock.call_at(3, battery(50))
    clock.call_at(4, battery(95))
    mission.run()
    assert trace(tags) == [
        *pair(2, "rover", "docked"),
        *pair(4, "rover", "battery_full"),
        *pair(4, "rover", "leave_dock"),
    ]


def test_interrupting_signal_boundary_event():
    drive = Drive()
    mission, tags = build(
        "boundary.bpmn",
        skills={"drive": drive},
        variables={"rover": {"drive_time": 20, "beats": 0}},
    )
    mission.clock.call_at(
        1.5, lambda: mission.bus.publish("/obstacle", {}, msgtype="std_msgs/msg/Empty")
    )
    mission.run()
    assert trace(tags) == [
        (0, "rover", "drive", "start"),
        *pair(1, "rover", "heartbeat"),
        *pair(1, "rover", "beat"),
        *pair(1.5, "rover", "obstacle?"),
        *pair(1.5, "rover", "avoid"),
    ]
    assert drive.cancelled and mission.clock.next_time() is None


def survey(blink_done=1):
    return [
        (0, "rover", "survey", "start"),
        (0, "rover", "blink", "start"),
        *pair(0, "rover", "led_on"),
        *pair(blink_done, "rover", "1_s"),
        *pair(blink_done, "rover", "led_off"),
        (blink_done, "rover", "blink", "complete"),
    ]


def test_event_sub_process_of_a_sub_process_and_a_building_block_inside_it():
    mission, tags = build("nested.bpmn", variables={"rover": {"abort_survey": False}})
    mission.clock.call_at(
        3, lambda: mission.bus.publish("/photo_request", {}, msgtype="std_msgs/msg/Empty")
    )
    mission.run()
    assert trace(tags) == [
        *survey(),
        *handler(3, "rover", "photos", "photo_request?", "take_photo"),
        *pair(11, "rover", "scan"),
        (11, "rover", "survey", "complete"),
        *pair(11, "rover", "report"),
    ]


@pytest.mark.parametrize("when", [0.5, 5])
def test_conditional_boundary_event_cancels_nested_scopes(when):
    mission, tags = build("nested.bpmn", variables={"rover": {"abort_survey": False}})
    rover = mission.engines["rover"]
    mission.clock.call_at(when, lambda: rover.set_variables(abort_survey=True))
    mission.clock.call_at(
        6, lambda: mission.bus.publish("/photo_request", {}, msgtype="std_msgs/msg/Empty")
    )
    mission.run()
    before = survey() if when > 1 else survey()[:4]  # the building block is cut short at 0.5 s
    assert trace(tags) == [
        *before,
        *pair(when, "rover", "abort_survey"),
        *pair(when, "rover", "abandon"),
    ]
    # the cut-short activities end with ate_abort, the innermost first
    cut = ["blink", "survey"] if when < 1 else ["survey"]
    aborted = [t for t in trace(tags, aborts=True) if t[3] == "ate_abort"]
    assert aborted == [(when, "rover", name, "ate_abort") for name in cut]
    assert mission.bus.topics() == []  # the 6 s photo request finds nobody listening
    mission.clock.run()
    assert len(tags) == len(before) + 4 + len(cut)


def test_conditional_event_reading_a_variable_not_set_yet_waits_for_it():
    mission, tags = build("start_events.bpmn", robots=["watcher"])  # no level yet
    watcher = mission.engines["watcher"]
    mission.clock.call_at(2, lambda: watcher.set_variables(level=9))
    mission.start()
    mission.clock.run(until=5)
    assert trace(tags) == [*pair(2, "watcher", "level_high"), *pair(2, "watcher", "alarm")]
