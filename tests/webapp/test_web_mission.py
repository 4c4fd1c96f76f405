"""The Mission page's data API on a simulated run stored with ``robotale ingest``: every answer
set against the log read with pandas and against the run's truth (what the simulator knew)."""

from __future__ import annotations

import json
import math
import re
from dataclasses import dataclass
from itertools import pairwise
from pathlib import Path

import pandas as pd
import pytest
from lxml import etree

CASE = "run_0001"
#: a message the drone sends a tractor, dropped once: a lost message to find near the cursor
FAULT = "drop:/closest_tractor,nth=1"
#: the truth samples poses at 2 Hz, the log at its own events: robots move up to 1 m/s
POSE_METRES = 0.6
#: a cursor this far from every activity's start and end tells active from not
MARGIN = 0.05
BPMN = "{http://www.omg.org/spec/BPMN/20100524/MODEL}"
#: the BPMN elements whose names are the activities the engines tag
ACTIVITY_TAGS = {"callActivity", "subProcess", "task", "scriptTask", "serviceTask", "userTask"}


@dataclass(frozen=True)
class StoredRun:
    name: str
    folder: Path
    log: pd.DataFrame
    truth: list[dict]
    model: Path


@pytest.fixture(scope="module")
def stored_run(app, neo4j_driver, tmp_path_factory) -> StoredRun:
    """One agri run (a message dropped) simulated, stored by ``robotale ingest`` and linked to
    its model, as a user does it."""
    from robotale.cli import main
    from robotale.ekg.columnar import stored_table
    from robotale.ekg.logs import delete_log
    from robotale.sim import scenarios
    from robotale.sim.batch import simulate_batch
    from robotale.sim.plans import plans
    from robotale.sim.worldspec import load_world
    from robotale.webapp.state import state

    folder = tmp_path_factory.mktemp("mission") / "agri"
    world = load_world(scenarios.world_file("agri"))
    simulate_batch(plans(world, "agri", runs=1, seed=2, faults=[FAULT]), folder, workers=0)
    name = "mission_agri"
    assert main(["ingest", str(folder), "--log", name, "--replace", "--rate", "2"]) == 0
    model = next(m for m in state(app).models.all() if m.name == "agri.bpmn")
    state(app).models.link(name, model.id)
    log = stored_table(neo4j_driver, name)
    truth_file = folder / CASE / "robotale-truth.jsonl"
    truth = [json.loads(line) for line in truth_file.read_text().splitlines()]
    yield StoredRun(name, folder, log, truth, scenarios.model_file("agri"))
    delete_log(neo4j_driver, name)


def api(client, path: str):
    response = client.get(path)
    assert response.status_code == 200, response.get_data(as_text=True)
    return response.get_json()


def run_events(run: StoredRun) -> tuple[pd.DataFrame, pd.Timestamp]:
    events = run.log[run.log["case:concept:name"] == CASE].sort_values(
        "time:timestamp", kind="stable"
    )
    return events, events["time:timestamp"].iloc[0]


def truth_activities(run: StoredRun) -> list[dict]:
    return [r for r in run.truth if r["kind"] == "activity"]


def normalised(name: str) -> str:
    return re.sub(r"[^a-z0-9]+", "_", name.lower()).strip("_")


def model_activities(model: Path) -> dict[str, dict[str, list[str]]]:
    """``{pool name: {activity: [element ids]}}`` read from the BPMN file with lxml."""
    tree = etree.parse(str(model))
    processes = {p.get("id"): p for p in tree.iter(f"{BPMN}process")}
    found: dict[str, dict[str, list[str]]] = {}
    for pool in tree.iter(f"{BPMN}participant"):
        names: dict[str, list[str]] = {}
        for element in processes[pool.get("processRef")].iter():
            tag = etree.QName(element).localname
            if tag in ACTIVITY_TAGS and element.get("name"):
                names.setdefault(normalised(element.get("name")), []).append(element.get("id"))
        found[pool.get("name")] = names
    return found


def pool_of(robot: str) -> str:
    return robot.split("_")[0].capitalize()


def cursor_times(run: StoredRun, count: int = 3) -> list[float]:
    """Moments spread over the run, away from every activity's start and end, at which every
    running activity is a named activity of the model (not a catch event or a timer)."""
    activities = truth_activities(run)
    start = run.truth[0]["start"]
    bounds = sorted({a[k] - start for a in activities for k in ("start", "end")})
    named = {a for pool in model_activities(run.model).values() for a in pool}
    end = bounds[-1]
    candidates: list[tuple[float, str]] = []
    for share in [i / 80 for i in range(8, 76)]:
        t = round(share * end, 2)
        if min(abs(t - b) for b in bounds) < MARGIN:
            continue
        running = truth_active(run, t)
        if not any(running.values()) or not all(
            a in named for a in (a for names in running.values() for a in names)
        ):
            continue
        candidates.append((t, repr(sorted(running.items()))))
    # spread over the run, each moment with other activities running than the one before
    chosen: list[float] = []
    doing: list[str] = []
    for t, running in candidates:
        if not chosen or (t - chosen[-1] > end / 10 and running != doing[-1]):
            chosen.append(t)
            doing.append(running)
    assert len(chosen) >= count, candidates
    return chosen[:count]


def truth_active(run: StoredRun, t: float) -> dict[str, list[str]]:
    start = run.truth[0]["start"]
    running: dict[str, list[str]] = {robot: [] for robot in run.truth[0]["robots"]}
    for a in truth_activities(run):
        end = a["end"] if a["end"] is not None else math.inf
        if a["start"] - start <= t < end - start:
            running[a["robot"]].append(a["activity"])
    return running


def truth_pose(run: StoredRun, robot: str, t: float) -> dict:
    """The truth's sample of ``robot`` nearest to ``t``."""
    start = run.truth[0]["start"]
    samples = [r for r in run.truth if r["kind"] == "sample" and r["robot"] == robot]
    return min(samples, key=lambda s: abs(s["t"] - start - t))


def test_state_at_three_moments_is_the_logs_and_the_truths(client, stored_run):
    events, start = run_events(stored_run)
    activities = model_activities(stored_run.model)
    base = f"/api/mission/{stored_run.name}/{CASE}"
    posed = 0
    for t in cursor_times(stored_run):
        state = api(client, f"{base}/state?t={t}")
        assert state["t"] == t
        assert set(state["robots"]) == set(stored_run.truth[0]["robots"])
        running = truth_active(stored_run, t)
        for robot, facts in state["robots"].items():
            mine = events[
                (events["robot"] == robot)
                & (events["time:timestamp"] <= start + pd.Timedelta(seconds=t))
            ]
            placed = mine.dropna(subset=["x"])
            if placed.empty:  # nothing recorded of it yet: the map does not guess
                assert facts["pose"] is None and facts["battery"] is None
            else:
                last = placed.iloc[-1]
                assert facts["pose"] == pytest.approx(
                    {"x": last["x"], "y": last["y"], "z": last["z"]}
                )
                # true where and when it was recorded (the log holds a robot's last record)
                recorded = (last["time:timestamp"] - start).total_seconds()
                sample = truth_pose(stored_run, robot, recorded)
                where = (facts["pose"]["x"], facts["pose"]["y"], facts["pose"]["z"])
                assert math.dist(where, (sample["x"], sample["y"], sample["z"])) < POSE_METRES
                assert facts["battery"] == pytest.approx(mine["battery"].dropna().iloc[-1])
                assert facts["battery"] == pytest.approx(100 * sample["battery"], abs=1.0)
                posed += 1
            assert sorted(facts["activities"]) == sorted(running[robot]), (robot, t)
            expected = sorted(
                i for a in running[robot] for i in activities[pool_of(robot)].get(a, [])
            )
            assert sorted(state["elements"].get(robot, [])) == expected, (robot, t)
    assert posed >= 6  # most robots are on the map at most of the three moments


def test_heading_is_the_direction_of_the_last_move(client, stored_run):
    events, start = run_events(stored_run)
    t = cursor_times(stored_run)[1]
    state = api(client, f"/api/mission/{stored_run.name}/{CASE}/state?t={t}")
    for robot, facts in state["robots"].items():
        mine = events[
            (events["robot"] == robot)
            & (events["time:timestamp"] <= start + pd.Timedelta(seconds=t))
        ]
        xy = mine.dropna(subset=["x"])[["x", "y"]]
        moves = xy.diff().dropna()
        moves = moves[(moves["x"] ** 2 + moves["y"] ** 2) ** 0.5 > 1e-3]
        if moves.empty:
            assert facts["heading"] is None
        else:
            dx, dy = moves.iloc[-1]
            assert facts["heading"] == pytest.approx(math.atan2(dy, dx))


def scratch_activities(events: pd.DataFrame, seconds: pd.Series) -> pd.DataFrame:
    """robot, activity, start, end (inf: never ended) of every activity instance, paired here
    first in first out per robot, activity and instance key, from the log's starts and
    completes (``inprogress`` samples left out)."""
    key = next((k for k in ("execution_id", "concept:instance", "msg_id") if k in events), None)
    rows = events.assign(_s=seconds)
    rows = rows[rows["lifecycle:transition"].isin(["start", "complete"])]
    if "lifecycle:state" in rows:
        rows = rows[rows["lifecycle:state"].astype("string").fillna("").ne("inprogress")]
    keys = ["robot", "concept:name"] + ([key] if key else [])
    found = []
    for group, mine in rows.groupby(keys, sort=False, dropna=False):
        waiting: list[float] = []
        for lifecycle, at in zip(mine["lifecycle:transition"], mine["_s"], strict=True):
            if lifecycle == "start":
                waiting.append(at)
            elif waiting:
                found.append((group[0], group[1], waiting.pop(0), at))
        found += [(group[0], group[1], begun, math.inf) for begun in waiting]
    return pd.DataFrame(found, columns=["robot", "activity", "start", "end"])


def scratch_last_message(messages: pd.DataFrame, robot: str, t: float) -> tuple[float, set]:
    """The time of ``robot``'s last message by ``t`` and the (msg_id, role) of those then."""
    sent = messages[(messages["sender"] == robot) & (messages["sent"] <= t)]
    received = messages[(messages["receiver"] == robot) & (messages["received"] <= t)]
    times = pd.concat([sent["sent"], received["received"]])
    if times.empty:
        return math.nan, set()
    last = times.max()
    return last, {(str(m), "sent") for m in sent.loc[sent["sent"] == last, "msg_id"]} | {
        (str(m), "received") for m in received.loc[received["received"] == last, "msg_id"]
    }


def test_state_from_time_arrays_equals_the_log_read_from_scratch(client, stored_run):
    """The state API answers from per-robot time arrays read once: at moments all over the
    run, on event times exactly (where at-or-before and before-the-end tell), each robot's
    pose, heading, battery, activities and last message equal what pandas reads from the
    stored log at that moment."""
    from robotale.enhancement.communication import message_table

    events, start = run_events(stored_run)
    seconds = (events["time:timestamp"] - start).dt.total_seconds()
    instances = scratch_activities(events, seconds)
    messages = message_table(events)
    for column, at in (("sent", "sent_at"), ("received", "received_at")):
        messages[column] = (messages[at] - start).dt.total_seconds()
    exact = sorted(set(instances["start"]) | set(instances["end"]) - {math.inf})
    moments = [0.0, *exact[:: max(1, len(exact) // 12)], float(seconds.max()), 1e9]
    checked = 0
    for t in moments:
        state = api(client, f"/api/mission/{stored_run.name}/{CASE}/state?t={t!r}")
        for robot, facts in state["robots"].items():
            mine = events[(events["robot"] == robot) & (seconds <= t)]
            placed = mine.dropna(subset=["x", "y"])
            if placed.empty:
                assert facts["pose"] is None and facts["heading"] is None
            else:
                last = placed.iloc[-1]
                assert facts["pose"] == {axis: float(last[axis]) for axis in ("x", "y", "z")}
                steps = placed[["x", "y"]].diff().dropna()
                steps = steps[(steps["x"] ** 2 + steps["y"] ** 2) ** 0.5 > 1e-3]
                if steps.empty:
                    assert facts["heading"] is None
                else:
                    dx, dy = steps.iloc[-1]["x"], steps.iloc[-1]["y"]
                    assert facts["heading"] == pytest.approx(math.atan2(dy, dx))
            levels = mine["battery"].dropna()
            assert facts["battery"] == (None if levels.empty else float(levels.iloc[-1]))
            running = instances[
                (instances["robot"] == robot) & (instances["start"] <= t) & (t < instances["end"])
            ]
            assert sorted(facts["activities"]) == sorted(running["activity"]), (robot, t)
            last_at, candidates = scratch_last_message(messages, robot, t)
            if not candidates:
                assert facts["last_message"] is None
            else:
                told = facts["last_message"]
                assert told["s"] == last_at and (told["msg_id"], told["role"]) in candidates
            checked += bool(facts["activities"]) + bool(facts["last_message"])
    assert checked >= 20  # the moments hold work and messages, not only empty answers


def test_flows_taken_grow_and_lie_in_the_model(client, stored_run):
    tree = etree.parse(str(stored_run.model))
    flows = {f.get("id") for f in tree.iter(f"{BPMN}sequenceFlow")}
    base = f"/api/mission/{stored_run.name}/{CASE}/state"
    counts = [api(client, f"{base}?t={t}")["flows"] for t in cursor_times(stored_run)]
    assert counts[-1] and set(counts[-1]) <= flows
    for earlier, later in pairwise(counts):
        assert all(later.get(flow, 0) >= n for flow, n in earlier.items())
    # by hand, from the model: the drone takes off (Drone_Flow_2 into the merge), explores
    # (Drone_Flow_Explore out of it) and explores again through Drone_Flow_Again
    start = stored_run.truth[0]["start"]
    last = cursor_times(stored_run)[-1]
    explores = [
        a
        for a in truth_activities(stored_run)
        if a["robot"] == "drone" and a["activity"] == "explore" and a["start"] - start <= last
    ]
    assert counts[-1]["Drone_Flow_2"] == 1
    assert counts[-1]["Drone_Flow_Explore"] == len(explores)
    assert counts[-1].get("Drone_Flow_Again", 0) == len(explores) - 1


def event_gateway_catches(model: Path) -> dict[str, set[str]]:
    """``{catch event's name, normalised: the catch events waited at with it}``, read with
    lxml: a catch event behind an event-based gateway is waited at with all of that gateway's
    catch events, any other alone."""
    tree = etree.parse(str(model))
    catches = {e.get("id"): e for e in tree.iter(f"{BPMN}intermediateCatchEvent")}
    gateways = {g.get("id") for g in tree.iter(f"{BPMN}eventBasedGateway")}
    flows = list(tree.iter(f"{BPMN}sequenceFlow"))
    found: dict[str, set[str]] = {}
    for ident, catch in catches.items():
        together = {ident}
        for flow in flows:
            if flow.get("targetRef") == ident and flow.get("sourceRef") in gateways:
                together |= {
                    f.get("targetRef")
                    for f in flows
                    if f.get("sourceRef") == flow.get("sourceRef") and f.get("targetRef") in catches
                }
        found.setdefault(normalised(catch.get("name") or ident), set()).update(together)
    return found


def test_a_robot_between_its_last_element_and_a_catch_waits_at_it(client, stored_run):
    """Midway between a robot's last event and the catch event it tags next (a message or a
    timer it waited for), the state names that catch event (with its event-based gateway's
    others) among the elements the robot waits at (a sub-process around it may be running);
    at any moment a robot waits only at catch events of its own pool and not at what it runs.
    The moments and the elements come from the log with pandas and the model with lxml."""
    events, start = run_events(stored_run)
    catches = event_gateway_catches(stored_run.model)
    base = f"/api/mission/{stored_run.name}/{CASE}/state"
    checked = 0
    for robot, mine in events.groupby("robot"):
        seconds = (mine["time:timestamp"] - start).dt.total_seconds().to_numpy()
        names = [normalised(a) for a in mine["concept:name"]]
        roles = mine["msg_role"].astype("string").fillna("").tolist()
        for position in range(1, len(names)):
            if names[position] not in catches or roles[position] == "send":
                continue
            if mine["lifecycle:transition"].iloc[position - 1] != "complete":
                continue
            before, caught = seconds[position - 1], seconds[position]
            if caught - before < 4 * MARGIN:
                continue
            t = round((before + caught) / 2, 3)
            state = api(client, f"{base}?t={t}")
            assert set(state["waiting"].get(robot, [])) >= catches[names[position]], (robot, t)
            checked += 1
    assert checked >= 3  # tractors wait for their next weed, the drone for a tractor's answer
    # a robot waits only at catch events of its own pool, never at what it is running
    pools = pool_catches(stored_run.model)
    for t in cursor_times(stored_run):
        state = api(client, f"{base}?t={t}")
        for robot, waits in state["waiting"].items():
            assert set(waits) <= pools[pool_of(robot)], (robot, t)
            assert not set(waits) & set(state["elements"].get(robot, [])), (robot, t)


def pool_catches(model: Path) -> dict[str, set[str]]:
    """``{pool name: its intermediate catch events' ids}``, read with lxml."""
    tree = etree.parse(str(model))
    processes = {p.get("id"): p for p in tree.iter(f"{BPMN}process")}
    found: dict[str, set[str]] = {}
    for pool in tree.iter(f"{BPMN}participant"):
        process = processes[pool.get("processRef")]
        catches = process.iter(f"{BPMN}intermediateCatchEvent")
        found[pool.get("name")] = {e.get("id") for e in catches}
    return found


def test_window_holds_what_the_log_holds_between_two_moments(client, stored_run):
    events, start = run_events(stored_run)
    seconds = (events["time:timestamp"] - start).dt.total_seconds()
    low, high = 20.0, 40.0
    window = api(client, f"/api/mission/{stored_run.name}/{CASE}/window?from={low}&to={high}")
    inside = events[seconds.between(low, high)]
    control = inside[inside["lifecycle:transition"] != "none"]
    assert len(window["events"]) == len(control)
    assert [e["activity"] for e in window["events"]] == control["concept:name"].tolist()
    for robot, rows in window["positions"].items():
        assert len(rows) == inside[(inside["robot"] == robot) & inside["x"].notna()].shape[0]
    start_truth = stored_run.truth[0]["start"]
    sent = {
        r["msg_id"]
        for r in stored_run.truth
        if r["kind"] == "send" and low <= r["t"] - start_truth <= high
    }
    assert sent <= {m["msg_id"] for m in window["messages"]}


def test_the_lost_message_is_a_moment_where_the_truth_sent_it(client, stored_run):
    summary = api(client, f"/api/mission/{stored_run.name}/{CASE}")
    start = stored_run.truth[0]["start"]
    delivered = {
        r["msg_id"]
        for r in stored_run.truth
        if r["kind"] == "delivery" and r["outcome"] == "delivered"
    }
    lost = [r for r in stored_run.truth if r["kind"] == "send" and r["msg_id"] not in delivered]
    moments = [m for m in summary["moments"] if m["kind"] == "lost message"]
    assert [m["s"] for m in moments] == pytest.approx([r["t"] - start for r in lost], abs=1e-3)
    assert summary["site"]["source"] == "world"
    assert summary["site"]["field"] == [10, 10]
    manifest = json.loads((stored_run.folder / CASE / "robotale-run.json").read_text())
    assert [(o["x"], o["y"]) for o in summary["site"]["objects"]] == [
        (o["x"], o["y"]) for o in manifest["setup"]["objects"]
    ]


def test_series_is_the_logs_column_per_robot(client, stored_run):
    events, _ = run_events(stored_run)
    data = api(client, f"/api/mission/{stored_run.name}/{CASE}/series?field=battery")
    for robot, points in data["robots"].items():
        mine = events[(events["robot"] == robot) & events["battery"].notna()]
        assert [v for _, v in points] == pytest.approx(mine["battery"].tolist())


def test_bad_requests_say_what_is_wrong(client, stored_run):
    base = f"/api/mission/{stored_run.name}"
    cases = {
        f"{base}/{CASE}/state?t=soon": "?t= must be a number",
        f"{base}/{CASE}/state": "?t= must be a number",
        f"{base}/{CASE}/window?from=5&to=1": "ends (1.0 s) before it starts",
        f"{base}/{CASE}/series?field=colour": "no numeric field 'colour'",
        f"{base}/run_9999/state?t=1": "no run 'run_9999'",
        f"/api/mission/no_such_log/{CASE}/state?t=1": "no_such_log",
    }
    for path, sentence in cases.items():
        response = client.get(path, headers={"Accept": "application/json"})
        assert response.status_code in (400, 404), path
        assert sentence in response.get_json()["error"], (path, response.get_json())


def throw_events(model: Path, pool: str) -> dict[str, list[str]]:
    """``{name, normalised: [ids]}`` of a pool's intermediate throw events, read with lxml."""
    tree = etree.parse(str(model))
    processes = {p.get("id"): p for p in tree.iter(f"{BPMN}process")}
    participant = next(p for p in tree.iter(f"{BPMN}participant") if p.get("name") == pool)
    found: dict[str, list[str]] = {}
    for element in processes[participant.get("processRef")].iter(f"{BPMN}intermediateThrowEvent"):
        found.setdefault(normalised(element.get("name") or ""), []).append(element.get("id"))
    return found


def test_deviations_are_marked_where_a_robot_left_its_model(
    app, client, stored_run, neo4j_driver, log_name
):
    """The engine's own run follows its model: no deviation at its end. The same run with the
    first ``get_position`` of tractor_1 removed from the log: the tractor's next step, sending
    its position, is a deviation from that moment on (the model sends only after getting the
    position), and nothing before it or of another robot is."""
    from robotale.ekg.build import build_ekg
    from robotale.webapp.state import state as app_state

    events, start = run_events(stored_run)
    end = (events["time:timestamp"].iloc[-1] - start).total_seconds()
    clean = api(client, f"/api/mission/{stored_run.name}/{CASE}/state?t={end}")
    assert clean["deviations"] == {}

    skipped = stored_run.log[
        (stored_run.log["robot"] == "tractor_1")
        & (stored_run.log["concept:name"] == "get_position")
    ]
    first = skipped["time:timestamp"].min()
    dropped = skipped.index[
        skipped["time:timestamp"]
        <= skipped.loc[skipped["lifecycle:transition"] == "complete", "time:timestamp"].min()
    ]
    build_ekg(neo4j_driver, stored_run.log.drop(dropped), log_name, replace=True)
    model = next(m for m in app_state(app).models.all() if m.name == "agri.bpmn")
    app_state(app).models.link(log_name, model.id)
    mine = events[(events["robot"] == "tractor_1") & (events["time:timestamp"] > first)]
    sent = mine[
        (mine["concept:name"] == "tractor_position!") & (mine["lifecycle:transition"] == "start")
    ]["time:timestamp"].iloc[0]
    at = (sent - start).total_seconds()
    base = f"/api/mission/{log_name}/{CASE}/state"
    assert api(client, f"{base}?t={at - 0.001}")["deviations"] == {}
    after = api(client, f"{base}?t={at}")["deviations"]
    assert set(after) == {"tractor_1"}
    assert set(after["tractor_1"]) >= set(
        throw_events(stored_run.model, "Tractor")["tractor_position"]
    )
    assert set(api(client, f"{base}?t={end}")["deviations"]) == {"tractor_1"}


def test_a_log_without_positions_or_model_still_answers(client, stored_run, neo4j_driver, log_name):
    from robotale.ekg.build import build_ekg

    bare = stored_run.log.drop(columns=["x", "y", "z"])
    build_ekg(neo4j_driver, bare, log_name, replace=True)
    summary = api(client, f"/api/mission/{log_name}/{CASE}")
    assert summary["has_positions"] is False
    assert summary["site"] == {"source": None}
    assert summary["model"] is None
    state = api(client, f"/api/mission/{log_name}/{CASE}/state?t=30")
    assert all(f["pose"] is None and f["heading"] is None for f in state["robots"].values())
    assert "elements" not in state
    assert "x" not in summary["signals"] and "battery" in summary["signals"]


# -- the page, in a real browser -------------------------------------------------------------

SHOWN = "document.getElementById('mission').dataset.shown"


def move_cursor(page, t: float) -> None:
    page.fill("#cursor", str(t))
    wait_for_shown(page, t)


def wait_for_shown(page, t: float) -> None:
    from browser import wait_for

    wait_for(page, f"Number({SHOWN}) === {t}")


def scroll_to_plots(page) -> None:
    """Bring the timeline and the plot into the window (the page draws each once a quarter
    of it is there) and wait until both are drawn."""
    from playwright.sync_api import expect

    for box in ("#mission-timeline", "#plot"):
        page.locator(box).scroll_into_view_if_needed()
    page.locator("#mission-timeline").scroll_into_view_if_needed()
    expect(page.locator("#mission-timeline")).to_have_attribute("data-drawn", "1")
    expect(page.locator("#plot")).to_have_attribute("data-field", re.compile("."))


def expected_view(run: StoredRun, t: float) -> dict:
    """What the page must show at ``t``, from the stored log with pandas and the model file
    with lxml (and the truth for the running activities)."""
    events, start = run_events(run)
    upto = events[events["time:timestamp"] <= start + pd.Timedelta(seconds=t)]
    positions = {}
    batteries = {}
    for robot, mine in upto.groupby("robot"):
        placed = mine.dropna(subset=["x"])
        if not placed.empty:
            last = placed.iloc[-1]
            positions[robot] = (last["x"], last["y"], last["z"])
        levels = mine["battery"].dropna()
        if not levels.empty:
            batteries[robot] = levels.iloc[-1]
    activities = model_activities(run.model)
    active = sorted(
        {
            element
            for robot, names in truth_active(run, t).items()
            for name in names
            for element in activities[pool_of(robot)].get(name, [])
        }
    )
    return {"positions": positions, "battery": batteries, "active": active}


def shown_view(page) -> dict:
    robots = page.eval_on_selector_all(
        "#map g.robot",
        "els => els.map(e => [e.dataset.robot, +e.dataset.x, +e.dataset.y, +e.dataset.z])",
    )
    values = page.eval_on_selector_all(
        "#plot-values tr[data-robot]", "els => els.map(e => [e.dataset.robot, e.dataset.value])"
    )
    marked = page.eval_on_selector_all(
        "#canvas .djs-element.active", "els => els.map(e => e.dataset.elementId)"
    )
    return {
        "positions": {robot: (x, y, z) for robot, x, y, z in robots},
        "battery": {robot: float(value) for robot, value in values if value},
        "active": sorted(marked),
        "timeline": page.evaluate(
            "document.getElementById('mission-timeline').layout.shapes[0].x0"
        ),
    }


@pytest.mark.browser
def test_mission_page_shows_the_run_at_the_cursor_in_every_view(page, stored_run, screenshot):
    from browser import wait_for
    from playwright.sync_api import expect

    times = cursor_times(stored_run)
    _, start = run_events(stored_run)
    page.goto(f"{page.base_url}/mission?log={stored_run.name}&case={CASE}&t={times[0]}")
    wait_for_shown(page, times[0])
    expect(page.locator("#canvas")).to_have_attribute("data-rendered", "1")
    scroll_to_plots(page)
    expect(page.locator("#plot")).to_have_attribute("data-field", "battery")
    expect(page.locator("#mission-timeline")).to_have_attribute("data-drawn", "1")
    expect(page.locator("#mission-missing")).to_be_hidden()
    assert page.locator("#map rect.field").count() == 1
    assert page.locator("#map g.base").count() == 2
    seen = []
    waited = 0
    for t in times:
        move_cursor(page, t)
        wait_for(page, "document.getElementById('canvas').dataset.active !== undefined")
        expected = expected_view(stored_run, t)
        shown = shown_view(page)
        assert shown["positions"].keys() == expected["positions"].keys(), t
        for robot, where in expected["positions"].items():
            assert shown["positions"][robot] == pytest.approx(where), (robot, t)
        assert shown["battery"] == pytest.approx(expected["battery"]), t
        assert shown["active"] == expected["active"], t
        # the catch events the state API says robots wait at are the ones marked waiting
        answer = page.request.get(
            f"{page.base_url}/api/mission/{stored_run.name}/{CASE}/state?t={t}"
        ).json()
        waits = sorted({i for ids in answer["waiting"].values() for i in ids})
        marked = page.eval_on_selector_all(
            "#canvas .djs-element.waiting", "els => els.map(e => e.dataset.elementId)"
        )
        assert sorted(marked) == waits, t
        waited += bool(waits)
        at = start + pd.Timedelta(seconds=t)
        assert pd.Timestamp(shown["timeline"], tz="UTC") == pytest.approx(
            at, abs=pd.Timedelta("2ms")
        )
        assert f"t={t:.2f}" in page.url
        seen.append(shown)
    screenshot(page, "mission")
    # one cursor, every view: the timeline's line moved each time, the map and the plot's
    # readings with the log (each equal to it above, and not the same at every moment)
    assert len({view["timeline"] for view in seen}) == len(times)
    assert waited  # some robot waits at a catch event at one of the moments at least
    for key in ("positions", "battery", "active"):
        assert len({repr(view[key]) for view in seen}) > 1, key


@pytest.mark.browser
def test_clicking_a_bar_a_finding_or_a_key_moves_the_cursor(page, stored_run):
    from browser import wait_for

    truth_start = stored_run.truth[0]["start"]
    # the Findings page's runs and the Timeline page link to the run's replay
    page.goto(f"{page.base_url}/findings?log={stored_run.name}")
    page.click(f"#runs-table a.mission-link[href*='case={CASE}']")
    wait_for_shown(page, 0)
    page.goto(f"{page.base_url}/timeline?log={stored_run.name}&case={CASE}")
    page.click("#mission-link")
    wait_for_shown(page, 0)
    assert f"case={CASE}" in page.url and f"log={stored_run.name}" in page.url
    page.locator("#mission-timeline").scroll_into_view_if_needed()
    wait_for(page, "document.getElementById('mission-timeline').dataset.drawn")

    # the longest bar of the timeline: the cursor goes to its start, an activity's true start
    index = page.evaluate(
        """() => {
            const bars = document.getElementById('mission-timeline')._fullData
                .filter((trace) => trace.type === 'bar');
            let best = null;
            bars.forEach((trace, k) => Array.from(trace.x).forEach((ms, j) => {
                if (!best || ms > best.ms) best = { k, j, ms }; }));
            return best;
        }"""
    )
    bar = page.locator("#mission-timeline g.trace.bars").nth(index["k"]).locator("g.point path")
    bar.nth(index["j"]).scroll_into_view_if_needed()
    box = bar.nth(index["j"]).bounding_box()
    page.mouse.move(box["x"] + box["width"] / 2, box["y"] + box["height"] / 2)
    page.mouse.click(box["x"] + box["width"] / 2, box["y"] + box["height"] / 2)
    wait_for(page, f"{SHOWN} !== '0'")
    moved = float(page.evaluate(SHOWN))
    starts = [a["start"] - truth_start for a in truth_activities(stored_run)]
    assert min(abs(moved - s) for s in starts) < 1e-3

    # the lost message, listed near the cursor: clicking it goes where the truth sent it
    lost = next(
        r["t"] - truth_start
        for r in stored_run.truth
        if r["kind"] == "send"
        and not any(
            d["kind"] == "delivery" and d["msg_id"] == r["msg_id"] and d["outcome"] == "delivered"
            for d in stored_run.truth
        )
    )
    move_cursor(page, round(lost + 10, 2))
    page.click("#moments li[data-kind='lost message']")
    wait_for(page, f"Math.abs(Number({SHOWN}) - {lost}) < 1e-3")

    # the arrow keys step to the next and the previous event of the log
    events, start = run_events(stored_run)
    control = events[events["lifecycle:transition"] != "none"]
    times = sorted(set(((control["time:timestamp"] - start).dt.total_seconds()).round(6)))
    here = float(page.evaluate(SHOWN))
    page.locator("body").press("ArrowRight")
    following = next(s for s in times if s > here + 1e-6)
    wait_for(page, f"Math.abs(Number({SHOWN}) - {following}) < 1e-6")
    page.locator("body").press("ArrowLeft")
    before = [s for s in times if s < following - 1e-6][-1]
    wait_for(page, f"Math.abs(Number({SHOWN}) - {before}) < 1e-6")


@pytest.mark.browser
def test_the_timeline_and_the_plot_are_drawn_when_scrolled_to(page, stored_run):
    """Below the first view the timeline and the plot say they are drawn when scrolled to
    (plotly takes the page's only thread for them) while the rest of the page is shown; in
    the window, each is drawn: the cursor's line where the cursor is, a line per robot with
    battery levels in the log."""
    from playwright.sync_api import expect

    events, start = run_events(stored_run)
    page.set_viewport_size({"width": 1400, "height": 700})
    page.goto(f"{page.base_url}/mission?log={stored_run.name}&case={CASE}&t=30")
    wait_for_shown(page, 30)
    expect(page.locator("#canvas")).to_have_attribute("data-rendered", "1")
    for box in ("#mission-timeline", "#plot"):
        expect(page.locator(f"{box} > .placeholder")).to_have_text("drawn when scrolled into view")
    assert page.evaluate("document.getElementById('mission-timeline').dataset.drawn") is None
    assert page.evaluate("document.getElementById('plot').dataset.field") is None
    # the readings at the cursor need no drawing
    robots = set(events.dropna(subset=["battery"])["robot"].astype(str))
    rows = page.eval_on_selector_all("#plot-values tr[data-robot]", "els => els.length")
    assert rows == len(robots)

    page.locator("#mission-timeline").scroll_into_view_if_needed()
    expect(page.locator("#mission-timeline")).to_have_attribute("data-drawn", "1")
    expect(page.locator("#mission-timeline > .placeholder")).to_have_count(0)
    line = page.evaluate("document.getElementById('mission-timeline').layout.shapes[0].x0")
    at = start + pd.Timedelta(seconds=30)
    assert pd.Timestamp(line, tz="UTC") == pytest.approx(at, abs=pd.Timedelta("2ms"))

    page.locator("#plot").scroll_into_view_if_needed()
    expect(page.locator("#plot")).to_have_attribute("data-field", "battery")
    expect(page.locator("#plot > .placeholder")).to_have_count(0)
    lines = page.evaluate("document.getElementById('plot')._fullData.map((t) => t.name)")
    assert set(lines) == robots


@pytest.mark.browser
def test_the_page_says_what_a_run_without_positions_or_model_lacks(
    page, stored_run, neo4j_driver, log_name
):
    from browser import wait_for
    from playwright.sync_api import expect

    from robotale.ekg.build import build_ekg

    build_ekg(neo4j_driver, stored_run.log.drop(columns=["x", "y", "z"]), log_name, replace=True)
    page.goto(f"{page.base_url}/mission?log={log_name}&case={CASE}&t=30")
    wait_for_shown(page, 30)
    expect(page.locator("#mission-missing")).to_contain_text("records no positions")
    expect(page.locator("#mission-missing")).to_contain_text("No model is linked")
    expect(page.locator("#map")).to_contain_text("no positions in this run")
    assert page.locator("#map g.robot").count() == 0
    wait_for(page, "document.querySelectorAll('#plot-values tr[data-robot]').length === 3")
    scroll_to_plots(page)
    expect(page.locator("#plot")).to_have_attribute("data-field", "battery")
    assert page.locator("#robots table tbody tr").count() == 3
