"""The dashboard computes what its pages show of a stored log once per build of the log and
keeps it beside the log's columnar copy: counted by the app's counter and by the files' times,
never by timing. The answers are compared with the same analysis of the CSV, done here."""

from __future__ import annotations

import json

import pandas as pd
import pytest

from robotale.discovery.graph import json_ready
from robotale.ekg import build_ekg
from robotale.ekg.columnar import log_build, results_folder, store_copy
from robotale.enhancement import spatial_perspective
from robotale.enhancement.findings import find
from robotale.enhancement.timeline import run_list
from robotale.eventlog.readers import read_log

PAGES = [
    "/api/findings?log={}",
    "/api/perspectives/bottlenecks?log={}",
    "/api/perspectives/spatial?log={}",
    "/api/perspectives/communication?log={}",
    "/api/perspectives/battery?log={}",
    "/api/perspectives/performance?log={}",
    "/api/perspectives/performance?log={}&activity=explore&robot=drone",
    "/api/timeline/runs?log={}",
    "/api/timeline?log={}",
]


@pytest.fixture
def thesis(neo4j_driver, log_name, thesis_csv) -> tuple[str, pd.DataFrame]:
    log = read_log(thesis_csv)
    entities = ["robot", "msg_id"]
    build_ekg(neo4j_driver, log, log_name, entities=entities, progress=False)
    store_copy(neo4j_driver, log_name, log)
    return log_name, log


def kept(driver, name: str) -> dict[str, float]:
    """The result files of the log's current build and their modification times."""
    folder = results_folder(log_build(driver, name))
    return {p.name: p.stat().st_mtime_ns for p in folder.iterdir()}


def computed(app, name: str) -> dict[str, int]:
    """How often the app computed each kind of result of the log ``name``."""
    from robotale.webapp.state import state

    return {kind: n for (log, kind), n in state(app).logs.computed.items() if log == name}


def visit_all(client, name: str) -> list[dict]:
    answers = []
    for url in PAGES:
        response = client.get(url.format(name))
        assert response.status_code == 200, (url, response.get_data(as_text=True))
        answers.append(response.json)
    return answers


def test_a_second_visit_and_a_restarted_dashboard_compute_nothing(
    app, web_settings, neo4j_driver, thesis
):
    from robotale.webapp import create_app
    from robotale.webapp.state import state

    name, _ = thesis
    first = visit_all(app.test_client(), name)
    made = computed(app, name)
    assert made == {"findings": 1, "perspective": 6, "runs": 1, "timeline": 1}
    files = kept(neo4j_driver, name)
    assert len(files) == len(PAGES)
    state(app).logs.forget(name)  # the memory cache evicted: the disk answers
    assert visit_all(app.test_client(), name) == first
    assert computed(app, name) == made and kept(neo4j_driver, name) == files
    restarted = create_app(web_settings)
    assert visit_all(restarted.test_client(), name) == first
    assert not computed(restarted, name) and kept(neo4j_driver, name) == files


def test_the_kept_answers_are_those_of_the_csv(app, thesis):
    name, log = thesis
    client = app.test_client()
    spatial = client.get(f"/api/perspectives/spatial?log={name}").json
    assert spatial == json.loads(json.dumps(json_ready(spatial_perspective(log).to_dict())))
    findings = client.get(f"/api/findings?log={name}").json
    expected = find(log).to_dict()
    assert findings["answers"] == json.loads(json.dumps(json_ready(expected["answers"])))
    runs = client.get(f"/api/timeline/runs?log={name}").json["runs"]
    assert [r["case"] for r in runs] == run_list(log)["case"].astype(str).tolist()


def test_a_new_build_is_computed_again(app, neo4j_driver, thesis):
    name, log = thesis
    client = app.test_client()
    client.get(f"/api/findings?log={name}")
    old = results_folder(log_build(neo4j_driver, name))
    assert computed(app, name) == {"findings": 1}
    drone = log[log["robot"] == "drone"].reset_index(drop=True)
    build_ekg(neo4j_driver, drone, name, entities=["robot"], replace=True, progress=False)
    store_copy(neo4j_driver, name, drone)
    findings = client.get(f"/api/findings?log={name}").json
    assert computed(app, name) == {"findings": 2}
    assert not old.exists()
    assert findings["answers"] == json.loads(
        json.dumps(json_ready(find(drone).to_dict()["answers"]))
    )


def test_storing_prepares_everything_the_pages_show_first(app, neo4j_driver, thesis):
    from robotale.results.findings import prepare
    from robotale.webapp.state import state

    name, _ = thesis
    prepare(neo4j_driver, state(app).logs, name)
    prepared = computed(app, name)
    files = kept(neo4j_driver, name)
    # findings, five perspectives, the class graph, the runs, the first run's timeline, the
    # Mission page's slow-activity limits, and its first run: its values and five tables
    mission = [f for f in files if f.startswith("mission-1-")]
    assert len(files) - len(mission) == 10
    assert len(mission) == 6 and sum(f.endswith(".parquet") for f in mission) == 5
    assert sum(f.startswith("slow-limits-") for f in files) == 1
    client = app.test_client()
    for url in [*PAGES[:6], *PAGES[7:], "/api/discover/ekg?log={}&by=robot"]:
        assert client.get(url.format(name)).status_code == 200
    assert computed(app, name) == prepared and kept(neo4j_driver, name) == files


def test_deleting_a_log_removes_its_copy_and_results(client, neo4j_driver, thesis):
    from robotale.ekg.columnar import log_folder

    name, _ = thesis
    assert client.get(f"/api/findings?log={name}").status_code == 200
    assert log_folder(name).is_dir()
    response = client.post("/logs/delete", data={"csrf_token": client.csrf, "name": name})
    assert response.status_code == 302
    assert not log_folder(name).exists()
    gone = client.get(f"/api/findings?log={name}")
    assert gone.status_code == 404 or "There is no log named" in gone.get_data(as_text=True)
