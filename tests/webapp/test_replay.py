"""``robotale serve --bag``: a simulated run's recording replayed on the Mission page without
storing it answers the Mission API exactly as the same recording stored by ``robotale ingest``;
a path that is no recording is one sentence naming it."""

from __future__ import annotations

import json
import re
import subprocess
import sys
import urllib.request
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path
from urllib.parse import parse_qs, urlparse

import pytest

from robotale.cli import main
from robotale.neo4j_server.server import free_port

CASE = "run_0001"
#: the moments compared, in seconds since the run's start (its length is added as the last)
MOMENTS = (0.0, 5.0, 20.0)


@dataclass(frozen=True)
class Served:
    url: str
    printed: str
    bag: Path


@pytest.fixture(scope="module")
def recorded(app, neo4j_driver, tmp_path_factory) -> Iterator[tuple[Path, str]]:
    """One agri run simulated and stored by ``robotale ingest`` as a user does it."""
    from robotale.ekg.logs import delete_log
    from robotale.sim import scenarios
    from robotale.sim.batch import simulate_batch
    from robotale.sim.plans import plans
    from robotale.sim.worldspec import load_world

    folder = tmp_path_factory.mktemp("replay") / "agri"
    world = load_world(scenarios.world_file("agri"))
    simulate_batch(plans(world, "agri", runs=1, seed=3), folder, workers=0)
    name = "replay_agri"
    assert main(["ingest", str(folder), "--log", name, "--replace"]) == 0
    yield folder, name
    delete_log(neo4j_driver, name)


@pytest.fixture(scope="module")
def served(recorded) -> Iterator[Served]:
    """``robotale serve --bag`` on the run's bag, in its own process, until the tests end."""
    bag = recorded[0] / CASE
    port = free_port()
    command = [sys.executable, "-m", "robotale", "serve", "--bag", str(bag), "--port", str(port)]
    process = subprocess.Popen(command, stderr=subprocess.PIPE, text=True)
    try:
        assert process.stderr is not None
        printed = ""
        for line in process.stderr:  # the address, printed once it listens
            if "dashboard at" in line:
                printed = line
                break
        yield Served(f"http://127.0.0.1:{port}", printed, bag)
    finally:
        process.terminate()
        process.wait(timeout=60)


def fetched(url: str) -> dict:
    with urllib.request.urlopen(url, timeout=120) as response:
        return json.loads(response.read())


def test_serve_bag_prints_the_mission_page_of_the_run(served):
    found = re.search(r"(http://\S+)", served.printed)
    assert found, served.printed
    address = urlparse(found.group(1))
    assert address.path == "/mission"
    assert parse_qs(address.query) == {"log": [served.bag.name], "case": [CASE]}
    page = urllib.request.urlopen(found.group(1), timeout=120)
    assert page.status == 200


def test_the_replay_answers_as_the_stored_log(served, recorded, client):
    _, name = recorded
    replayed = f"{served.url}/api/mission/{served.bag.name}/{CASE}"
    summary = fetched(replayed)
    stored = client.get(f"/api/mission/{name}/{CASE}").get_json()
    assert summary["site"]["field"] and summary["site"] == stored["site"]
    assert {k: v for k, v in summary.items() if k != "model"} == {
        k: v for k, v in stored.items() if k != "model"
    }
    poses = []
    for t in (*MOMENTS, summary["duration"]):
        state = fetched(f"{replayed}/state?t={t}")
        assert state == client.get(f"/api/mission/{name}/{CASE}/state?t={t}").get_json(), t
        poses.append({robot: found["pose"] for robot, found in state["robots"].items()})
    assert len(poses[-1]) == 3 and all(poses[-1].values())  # every robot has moved by the end
    assert poses[0] != poses[-1]
    for path in ("/api/timeline/runs?log={}", "/api/timeline?log={}&case=" + CASE):
        found = fetched(served.url + path.format(served.bag.name))
        assert found == client.get(path.format(name)).get_json(), path
    window = fetched(f"{replayed}/window?from=5&to=30")
    assert window == client.get(f"/api/mission/{name}/{CASE}/window?from=5&to=30").get_json()
    assert window["events"], "the window holds events"


@pytest.mark.parametrize("kind", ["missing", "file", "empty folder"])
def test_a_path_that_is_no_recording_is_one_sentence(tmp_path, capsys, kind):
    path = tmp_path / "not-a-bag"
    if kind == "file":
        path.write_text("time,activity\n")
    elif kind == "empty folder":
        path.mkdir()
    code = main(["serve", "--bag", str(path), "--port", str(free_port())])
    message = capsys.readouterr().err.strip()
    assert code == 1
    assert message.startswith("robotale: ") and "\n" not in message, message
    assert str(path) in message, message


@pytest.mark.browser
def test_the_mission_page_draws_a_replayed_bag(page, app, recorded):
    """The page itself on a replay, in headless Chromium: every view drawn, the robots on the
    map where the replay's state API puts them."""
    from browser import wait_for
    from playwright.sync_api import expect

    from robotale.results.replay import open_replay
    from robotale.webapp.serve import add_replay, mission_path
    from robotale.webapp.state import state

    replay = open_replay(recorded[0] / CASE)
    add_replay(app, replay)
    try:
        page.goto(f"{page.base_url}{mission_path(replay)}&t=20")
        wait_for(page, "Number(document.getElementById('mission').dataset.shown) === 20")
        # each drawn once it is scrolled into the window
        page.locator("#plot").scroll_into_view_if_needed()
        page.locator("#mission-timeline").scroll_into_view_if_needed()
        expect(page.locator("#mission-timeline")).to_have_attribute("data-drawn", "1")
        expect(page.locator("#plot")).to_have_attribute("data-field", "battery")
        assert page.locator("#map rect.field").count() == 1
        shown = page.eval_on_selector_all(
            "#map g.robot", "els => els.map(e => [e.dataset.robot, +e.dataset.x, +e.dataset.y])"
        )
        robots = replay.run(CASE).state(20.0)["robots"]
        expected = {r: (s["pose"]["x"], s["pose"]["y"]) for r, s in robots.items() if s["pose"]}
        drawn = {r: (x, y) for r, x, y in shown}
        assert expected and drawn.keys() == expected.keys()
        for robot, where in expected.items():
            assert drawn[robot] == pytest.approx(where), robot
    finally:
        state(app).replays.pop(replay.name)
