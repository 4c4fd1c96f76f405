"""Timer start events start their process (Mission.run and ``fame run``), ``fame run``'s
clock starts now or at ``--start`` so ``timeDate`` timers fire, and a run stopped by
``--until`` with robots still working exits non-zero saying where they are."""

from datetime import UTC, datetime

from fame_suite import MODELS, run

from robotale.cli import main

EIGHT = datetime(2024, 5, 1, 8, tzinfo=UTC).timestamp()
ROBOTS = ["waiter", "alarm_clock", "ticker"]


def starts(tags, activity):
    return [t.stamp for t in tags if t.activity == activity and t.lifecycle == "start"]


def test_mission_run_waits_for_timer_start_events():
    begin = EIGHT - 10  # ten seconds before the alarm's date
    mission, tags = run("timer_starts.bpmn", robots=ROBOTS, start=begin)
    assert starts(tags, "serve") == [begin + 3]
    assert starts(tags, "ring") == [EIGHT]
    assert starts(tags, "tick") == [begin + 2, begin + 4]  # R2/PT2S: twice, 2 s apart
    assert mission.done and mission.clock.now() == EIGHT + 5  # after the snooze
    assert {r: e.completed for r, e in mission.engines.items()} == {
        "waiter": 1,
        "alarm_clock": 1,
        "ticker": 2,
    }


def test_a_past_date_fires_at_once():
    _, tags = run("timer_starts.bpmn", robots=ROBOTS, start=EIGHT + 60)
    assert starts(tags, "ring") == [EIGHT + 60]


def test_fame_run_starts_its_clock_at_start_and_fires_dates(capsys):
    model = str(MODELS / "timer_starts.bpmn")
    assert main(["fame", "run", model, "--start", "2024-05-01T07:59:50Z"]) == 0
    captured = capsys.readouterr()
    rows = [line.split("\t") for line in captured.out.splitlines()]
    assert ["    10.000", "alarm_clock", "ring", "start"] in rows
    assert ["     3.000", "waiter", "serve", "complete"] in rows
    # R2/PT2S: the cycle starts the ticker twice, 2 s apart
    assert [r[0] for r in rows if r[1:4] == ["ticker", "tick", "start"]] == [
        "     2.000",
        "     4.000",
    ]
    assert "# done at 15.000 s" in captured.err


def test_fame_run_starts_now_by_default(capsys):
    # now is past 2024-05-01, so the date fires at once: the clock does not start in 1970
    assert main(["fame", "run", str(MODELS / "timer_starts.bpmn")]) == 0
    rows = [line.split("\t") for line in capsys.readouterr().out.splitlines()]
    assert ["     0.000", "alarm_clock", "ring", "start"] in rows


def test_an_unfinished_run_exits_non_zero_and_says_where_robots_are(capsys):
    model = str(MODELS / "timer_starts.bpmn")
    code = main(["fame", "run", model, "--start", "2024-05-01T07:59:50Z", "--until", "12"])
    err = capsys.readouterr().err
    assert code == 1
    assert "# still running at 12.000 s" in err
    assert "# alarm_clock is at intermediateCatchEvent a_snooze (snooze)" in err


def test_a_run_waiting_only_for_a_timer_start_is_not_a_failure(capsys):
    model = str(MODELS / "timer_starts.bpmn")
    code = main(
        [
            "fame",
            "run",
            model,
            "--robots",
            "alarm_clock",
            "--start",
            "2024-05-01T07:00:00Z",
            "--until",
            "60",
        ]
    )
    assert code == 0
    assert "# waiting for a timer at 60.000 s" in capsys.readouterr().err
