"""A live run on the dashboard: tags stored one by one by the monitor's own writer
(:class:`robotale.ekg.live.LiveLog`), the Mission API answering on what is stored so far, set
against the tags written here, and the Mission page following the run's end in a real
Chromium unless the user moved the cursor back."""

from __future__ import annotations

import time
import uuid

import pytest

from robotale.fame_runtime.tags import Tag

#: the run's first tag, seconds since the Unix epoch
T0 = 1_800_000_000.0


@pytest.fixture
def live(neo4j_driver):
    from robotale.ekg.live import LiveLog, delete_live

    log = LiveLog(neo4j_driver, f"live_{uuid.uuid4().hex[:8]}")
    yield log
    delete_live(neo4j_driver, log.name)


def tags(log, rows: list[tuple[float, str, str, str]]) -> None:
    for s, robot, activity, lifecycle in rows:
        log.append(Tag(T0 + s, robot, activity, lifecycle))


def test_the_mission_api_answers_on_what_the_monitor_stored_so_far(client, live):
    api = f"/api/mission/{live.name}/{live.name}"
    assert client.get(api).status_code == 400  # nothing stored yet: no run of that name
    tags(live, [(0, "rover", "survey", "start"), (1.5, "drone", "scan", "start")])
    first = client.get(api).json
    # stamps travel as their messages' nanoseconds, a float's product off by some 100 ns
    assert first["live"] is True and first["duration"] == pytest.approx(1.5, abs=1e-6)
    state = client.get(f"{api}/state?t=1.0").json
    assert state["robots"]["rover"]["activities"] == ["survey"]
    assert state["robots"]["drone"]["activities"] == []
    tags(live, [(4.0, "rover", "survey", "complete"), (5.25, "rover", "dock", "start")])
    grown = client.get(api).json
    assert grown["duration"] == pytest.approx(5.25, abs=1e-6)
    state = client.get(f"{api}/state?t=4.5").json
    assert state["robots"]["rover"]["activities"] == []
    assert state["robots"]["drone"]["activities"] == ["scan"]
    state = client.get(f"{api}/state?t=5.25").json
    assert state["robots"]["rover"]["activities"] == ["dock"]
    runs = client.get(f"/api/timeline/runs?log={live.name}").json["runs"]
    assert [r["case"] for r in runs] == [live.name]


def test_a_look_waiting_for_the_run_to_grow_answers_with_the_tag_stored_meanwhile(client, live):
    """A page following the run asks with the number of events it holds: the answer comes
    once a tag is stored (here from another thread, half a second later), not at the wait's
    end, and holds what is new from ``since`` on."""
    import threading

    api = f"/api/mission/{live.name}/{live.name}"
    tags(live, [(0, "rover", "survey", "start")])
    held = client.get(api).json
    later = threading.Timer(0.5, tags, (live, [(2.5, "rover", "survey", "complete")]))
    later.start()
    began = time.monotonic()
    fresh = client.get(f"{api}?since=1&known={held['events']}&wait=30").json
    later.join()
    whole = client.get(api).json  # the whole summary of the run grown
    assert fresh["events"] == whole["events"] > held["events"]
    assert fresh["duration"] == pytest.approx(2.5, abs=1e-6)
    assert fresh["event_times"] == [s for s in whole["event_times"] if s >= 1] != []
    assert fresh["times_before"] == len([s for s in whole["event_times"] if s < 1])
    assert fresh["instances"] == whole["instances"]  # the one instance, ended after 1 s
    assert time.monotonic() - began < 30  # told before the wait ran out


def test_the_window_and_state_asked_with_the_summarys_events_answer_on_that_run(client, live):
    """A look's window and state asked with the events its summary showed answer on the run
    that summary was made of, though a tag was stored since (the next look reads it); asked
    without, on the run as stored; a number of events that is not one is refused."""
    api = f"/api/mission/{live.name}/{live.name}"
    tags(live, [(0, "rover", "survey", "start"), (2, "drone", "scan", "start")])
    shown = client.get(api).json
    tags(live, [(3, "rover", "survey", "complete")])
    held = f"&events={shown['events']}"
    state = client.get(f"{api}/state?t=3{held}").json
    assert state["robots"]["rover"]["activities"] == ["survey"]  # as the summary's run had it
    window = client.get(f"{api}/window?from=0&to=3{held}").json
    assert window == client.get(f"{api}/window?from=0&to=3{held}").json
    state = client.get(f"{api}/state?t=3").json
    assert state["robots"]["rover"]["activities"] == []  # the run as stored: survey over
    grown = client.get(f"{api}/window?from=0&to=3").json
    assert len(grown["events"]) == len(window["events"]) + 1
    assert client.get(f"{api}/state?t=3&events=some").status_code == 400


def test_a_new_run_of_the_same_name_replaces_the_one_read(client, live, neo4j_driver):
    """A reader that kept a longer run of that name reads the new one from its start; the
    run's count is the new run's."""
    from robotale.ekg.live import LiveLog
    from robotale.results.live import live_counts

    api = f"/api/mission/{live.name}/{live.name}"
    tags(live, [(0, "rover", "survey", "start"), (1, "rover", "survey", "complete")])
    tags(live, [(2, "rover", "dock", "start")])
    assert client.get(api).json["duration"] == pytest.approx(2.0, abs=1e-6)
    assert live_counts(neo4j_driver, live.name) == (3, 0)
    again = LiveLog(neo4j_driver, live.name)  # the monitor started again: a new run
    assert live_counts(neo4j_driver, live.name) == (0, 0)
    tags(again, [(10, "drone", "scan", "start"), (13, "drone", "scan", "complete")])
    assert live_counts(neo4j_driver, live.name) == (2, 0)
    grown = client.get(api).json
    assert grown["robots"] == ["drone"] and grown["duration"] == pytest.approx(3.0, abs=1e-6)


def test_the_state_follows_odometry_stored_in_batches_late_ones_too(client, live, neo4j_driver):
    """Poses come in batches beside the tags, a later batch holding a sample older than one
    already read: at moments between the samples, each robot's pose and heading are its
    last sample's and last move's among all the samples written, read here with pandas; the
    run's counts are the tags and samples written."""
    import math

    import pandas as pd

    from robotale.ekg.live import Pose
    from robotale.results.live import live_counts

    api = f"/api/mission/{live.name}/{live.name}"
    tags(live, [(0, "rover", "survey", "start"), (0, "drone", "scan", "start")])
    written: list[Pose] = []
    batches = [
        [Pose(T0 + s / 10, r, s * 0.1 * (1 if r == "rover" else -1), s * 0.05, 0.0)
         for s in range(1, 20) for r in ("rover", "drone")],
        [Pose(T0 + s / 10, "rover", 2.0, 1.0 + s * 0.2, 0.0) for s in range(20, 40)],
        # a late drone sample (older than its last one read) and a standing rover
        [Pose(T0 + 0.55, "drone", 9.0, 9.0, 1.0), Pose(T0 + 4.5, "rover", 2.0, 8.8, 0.0)],
    ]  # fmt: skip
    for batch in batches:
        live.poses(batch)
        written += batch
        assert live_counts(neo4j_driver, live.name) == (2, len(written))
        table = pd.DataFrame(written).sort_values("stamp", kind="stable")
        table["s"] = table["stamp"] - T0
        assert client.get(api).status_code == 200
        for t in (0.05, 0.57, 1.23, 3.01, 4.7):
            state = client.get(f"{api}/state?t={t}").json
            for robot in ("rover", "drone"):
                mine = table[(table["robot"] == robot) & (table["s"] <= t)]
                facts = state["robots"][robot]
                if mine.empty:
                    assert facts["pose"] is None, (robot, t)
                    continue
                last = mine.iloc[-1]
                assert facts["pose"] == {"x": last["x"], "y": last["y"], "z": last["z"]}
                steps = mine[["x", "y"]].diff().dropna()
                steps = steps[(steps["x"] ** 2 + steps["y"] ** 2) ** 0.5 > 1e-3]
                if steps.empty:
                    assert facts["heading"] is None, (robot, t)
                else:
                    dy, dx = steps.iloc[-1]["y"], steps.iloc[-1]["x"]
                    assert facts["heading"] == pytest.approx(math.atan2(dy, dx)), (robot, t)


@pytest.mark.browser
def test_the_mission_page_follows_a_live_run_until_moved_back(page, live):
    from browser import wait_for

    root = "document.getElementById('mission')"
    tags(live, [(0, "rover", "survey", "start"), (2.0, "rover", "survey", "complete")])
    page.goto(f"{page.base_url}/mission?log={live.name}")
    wait_for(page, f"{root}.dataset.live === '1' && Number({root}.dataset.t) === 2")
    tags(live, [(6.0, "rover", "dock", "start")])
    # the cursor follows the run's end as it grows, and the robot's table says what it does
    wait_for(page, f"Number({root}.dataset.t) === 6 && Number({root}.dataset.shown) === 6")
    assert "dock" in page.inner_text("#robots")
    # moved back, the cursor stays where it was put while the run grows
    page.evaluate(
        "() => { const s = document.getElementById('cursor'); s.value = '1';"
        " s.dispatchEvent(new Event('input')); }"
    )
    tags(live, [(9.0, "rover", "dock", "complete")])
    wait_for(page, "Number(document.getElementById('cursor').max) === 9")
    assert page.evaluate(f"Number({root}.dataset.t)") == 1
    assert page.evaluate(f"{root}.dataset.following") == "0"
    # back at the end, it follows again
    page.keyboard.press("End")
    tags(live, [(12.0, "rover", "survey", "start")])
    wait_for(page, f"Number({root}.dataset.t) === 12")


def test_a_run_grown_in_batches_equals_the_run_made_of_all_its_tags(
    live, neo4j_driver, monkeypatch
):
    """Tags stored in batches, one closing an activity opened in an earlier one, a message
    sent in one and received in a later one, another older than the last look's open
    activities: after each look, the run the reader grew equals the one made afresh of every
    tag written (events, instances, messages, moments, the state at moments in between),
    and some look made only the tail again."""
    import pandas as pd

    from robotale.enhancement.mission import mission_run
    from robotale.results import live as reading

    remade: list[tuple[int, int]] = []  # (tags made again, tags held) at each making
    tag_frame = reading._tag_frame

    def counted(name, held, heard, chosen):
        remade.append((len(chosen), len(held)))
        return tag_frame(name, held, heard, chosen)

    monkeypatch.setattr(reading, "_tag_frame", counted)
    batches = [
        [(0, "rover", "survey", "start", ""), (1.5, "drone", "scan", "start", ""),
         (2, "rover", "survey", "complete", ""), (2.5, "rover", "call", "start", "send")],
        [(2.5, "rover", "call", "complete", "send"), (3, "rover", "dock", "start", ""),
         (4, "drone", "scan", "complete", "")],
        [(4.5, "drone", "hear", "start", "receive"), (4.5, "drone", "hear", "complete", "receive"),
         (6, "rover", "dock", "complete", ""), (6, "drone", "scan", "start", "")],
        [(7, "rover", "survey", "start", ""), (8, "drone", "scan", "complete", ""),
         (9, "rover", "survey", "complete", "")],
        [(8.5, "drone", "land", "start", ""), (9.5, "drone", "land", "complete", "")],
        [(1, "drone", "late", "start", ""), (1.2, "drone", "late", "complete", "")],
    ]  # fmt: skip
    written: list[Tag] = []
    held: dict | None = None  # the summary as a following page holds it, grown look by look
    wholes = 0  # looks that told the page to ask for the whole summary again
    for batch in batches:
        for s, robot, activity, lifecycle, role in batch:
            tag = Tag(T0 + s, robot, activity, lifecycle, "m1" if role else "", role)
            live.append(tag)
            written.append(tag)
        run = reading.live_replay(neo4j_driver, live.name).run(live.name)
        whole = mission_run(reading.tags_events(live.name, written), live.name)
        for table in ("events", "instances", "messages", "moments"):
            pd.testing.assert_frame_equal(getattr(run, table), getattr(whole, table), obj=table)
        assert (run.robots, run.duration) == (whole.robots, whole.duration)
        assert run.summary() == whole.summary()  # its records partly kept from the last look
        # the page asks for what may have changed since a little before the end it held
        since = 0.0 if held is None else max(0.0, held["duration"] - 3.0)
        grown = followed(held, run.summary(since))
        wholes += grown is None
        held = grown if grown is not None else run.summary()
        assert held == whole.summary(), since
        for t in (0.5, 2.5, 4.5, 6.0, 8.7, 9.5):
            assert run.state(t) == whole.state(t), t
    assert wholes == 1  # the late tags (older than the end held less 3 s) were told
    assert len(whole.messages) == 1 and whole.messages["receiver"].iloc[0] == "drone"
    assert any(chosen < held for chosen, held in remade)


def followed(held: dict | None, fresh: dict) -> dict | None:
    """The summary a page held grown by ``fresh`` (one asked for ``since`` some time), as the
    Mission page grows it: the event times and the instances over before then kept; None
    when the page must ask for the whole summary (it holds other earlier times)."""
    since, before = fresh.pop("since"), fresh.pop("times_before")
    if held is None:
        return fresh
    kept = [s for s in held["event_times"] if s < since]
    if len(kept) != before:
        return None
    times = kept + fresh["event_times"]
    over = [i for i in held["instances"] if i["end"] is not None and i["end"] < since]
    instances = sorted(over + fresh["instances"], key=lambda i: (i["start"], i["robot"]))
    return {**fresh, "event_times": times, "instances": instances}
