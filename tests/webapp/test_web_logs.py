"""The Logs page through the app: upload, column choice, ingest into the real Neo4j, delete."""

from __future__ import annotations

import csv
import html
import io
import json
import re
import subprocess
import sys
import time
import zipfile
from pathlib import Path

import pytest

from robotale.webapp import create_app


def text(response) -> str:
    return html.unescape(response.get_data(as_text=True))


def upload(client, name: str, data: bytes, mapping: str = "", case_gap: str = ""):
    form = {"csrf_token": client.csrf, "file": (io.BytesIO(data), name), "mapping": mapping}
    return client.post(
        "/logs/upload",
        data={**form, "case_gap": case_gap},
        content_type="multipart/form-data",
    )


def wait(client, job_id: str, seen: list | None = None, timeout: float = 300) -> dict:
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        job = client.get(f"/api/jobs/{job_id}").json
        if seen is not None:
            seen.append(job)
        if job["finished"]:
            return job
        time.sleep(0.05)
    raise AssertionError(f"job {job_id} did not finish in {timeout} s")


def read_step(
    client, name: str, data: bytes, mapping: str = "", case_gap: str = ""
) -> tuple[str, str]:
    """Upload and wait until it is read: the upload's token and the column page."""
    response = upload(client, name, data, mapping, case_gap)
    assert response.status_code == 302, text(response)
    token, job_id = re.search(r"/logs/upload/(\w+)\?job=(\w+)", response.location).groups()
    job = wait(client, job_id)
    assert job["error"] is None, job["error"]
    page = text(client.get(response.location))
    return token, page


def ingest(client, token: str, fields: dict) -> tuple[dict, list[dict]]:
    response = client.post(f"/logs/upload/{token}", data={"csrf_token": client.csrf, **fields})
    assert response.status_code == 302, text(response)
    job_id = re.search(r"/logs/jobs/(\w+)", response.location).group(1)
    seen: list[dict] = []
    return wait(client, job_id, seen), seen


def stored(client) -> dict[str, dict]:
    return {log["name"]: log for log in client.get("/api/logs").json["logs"]}


def test_thesis_csv_is_stored_with_the_chosen_columns(
    client, thesis_csv, log_name, web_settings, neo4j_driver
):
    token, page = read_step(client, "robotic_data.csv", thesis_csv.read_bytes())
    with thesis_csv.open() as stream:
        rows = list(csv.DictReader(stream))
    assert f"{len(rows)} events" in page
    for column in ("time", "activity", "msg_id", "x", "field", "robot"):  # resource is the robot
        assert f'data-column="{column}"' in page
    assert re.search(r'value="robot" checked\s+aria-label="robot is an entity"', page)

    kept = ["msg_id", "msg_role", "x", "y", "z", "robot", "event_id"]  # not: field, msg_payload
    job, _ = ingest(client, token, {"name": log_name, "store": kept, "entity": ["robot", "msg_id"]})
    assert job["error"] is None and job["stage"] == "done"
    assert job["result"]["events"] == len(rows)

    log = stored(client)[log_name]
    assert log["events"] == len(rows) and log["status"] == "complete"
    assert sorted(log["entityTypes"]) == ["msg_id", "robot"]
    assert "activity+robot" in log["classTypes"]
    records, _, _ = neo4j_driver.execute_query(
        "MATCH (e:Event {log: $log}) UNWIND keys(e) AS key RETURN collect(DISTINCT key) AS keys",
        log=log_name,
    )
    keys = set(records[0]["keys"])
    assert {"activity", "timestamp", "lifecycle", "x", "robot", "msg_id"} <= keys
    assert not keys & {"field", "msg_payload"}
    robots, _, _ = neo4j_driver.execute_query(
        "MATCH (n:Entity {log: $log, type: 'robot'}) RETURN collect(n.id) AS ids", log=log_name
    )
    assert sorted(robots[0]["ids"]) == sorted({row["resource"] for row in rows})
    assert list(web_settings.upload_dir.iterdir()) == []  # the upload is gone


def test_a_refused_choice_keeps_nothing_and_lets_the_user_choose_again(
    client, thesis_csv, log_name, web_settings, graph_counts
):
    token, _ = read_step(client, "robotic_data.csv", thesis_csv.read_bytes())
    before = graph_counts()
    response = client.post(
        f"/logs/upload/{token}",
        data={"csrf_token": client.csrf, "name": log_name, "entity": ["no_such_column"]},
    )
    assert response.status_code == 400
    assert "The log has no column 'no_such_column'" in text(response)
    unnamed = client.post(
        f"/logs/upload/{token}", data={"csrf_token": client.csrf, "name": " ", "entity": "robot"}
    )
    assert unnamed.status_code == 400 and "Give the log a name" in text(unnamed)
    assert graph_counts() == before
    # the upload is still there for a second try with a valid choice
    job, _ = ingest(client, token, {"name": log_name, "store": [], "entity": ["robot"]})
    assert job["error"] is None
    assert list(web_settings.upload_dir.iterdir()) == []


def test_an_existing_name_is_refused_unless_replaced(client, thesis_csv, log_name):
    token, _ = read_step(client, "a.csv", thesis_csv.read_bytes())
    ingest(client, token, {"name": log_name, "entity": ["robot"]})
    first = stored(client)[log_name]

    token, _ = read_step(client, "b.csv", thesis_csv.read_bytes())
    job, _ = ingest(client, token, {"name": log_name, "entity": ["robot", "msg_id"]})
    assert f"A log named {log_name!r} already exists" in job["error"]
    assert stored(client)[log_name]["entityTypes"] == first["entityTypes"] == ["robot"]

    token, _ = read_step(client, "c.csv", thesis_csv.read_bytes())
    job, _ = ingest(
        client, token, {"name": log_name, "entity": ["robot", "msg_id"], "replace": "on"}
    )
    assert job["error"] is None
    assert sorted(stored(client)[log_name]["entityTypes"]) == ["msg_id", "robot"]


def test_a_file_that_is_no_log_fails_while_reading_and_is_deleted(client, web_settings):
    response = upload(client, "broken.csv", b"when,what\nyesterday,nothing\n")
    job_id = re.search(r"job=(\w+)", response.location).group(1)
    job = wait(client, job_id)
    assert job["error"].startswith("'broken.csv' has no activity column")
    assert str(web_settings.upload_dir) not in job["error"]
    assert job["error"] in text(client.get(response.location))
    assert list(web_settings.upload_dir.iterdir()) == []


def test_columns_named_otherwise_are_mapped(client, log_name):
    data = (
        b"Zeit,Aktion,Roboter\n"
        b"2023-05-16T10:00:00Z,explore,drone\n"
        b"2023-05-16T10:00:05Z,land,drone\n"
    )
    token, page = read_step(
        client, "german.csv", data, mapping="Zeit=time, Aktion=activity, Roboter=robot"
    )
    assert 'data-column="activity"' in page and 'data-column="robot"' in page
    job, _ = ingest(client, token, {"name": log_name, "entity": ["robot"]})
    assert job["error"] is None and job["result"]["events"] == 2
    bad = upload(client, "german.csv", data, mapping="Zeit")
    assert bad.status_code == 400 and "is not COLUMN=FIELD" in text(bad)


def test_a_file_of_another_type_is_refused_at_once(client, web_settings):
    response = upload(client, "notes.txt", b"hello")
    assert response.status_code == 400
    assert "is not an event log robotale reads" in text(response)
    assert list(web_settings.upload_dir.iterdir()) == []


def test_uploads_over_the_limit_are_refused(neo4j_server, web_settings, tmp_path):
    import dataclasses

    app = create_app(dataclasses.replace(web_settings, upload_dir=tmp_path, upload_limit_mb=1))
    client = app.test_client()
    page = client.get("/logs").get_data(as_text=True)
    token = re.search(r'csrf-token" content="([^"]+)"', page).group(1)
    big = b"time,activity\n" + b"2023-05-16T10:00:00Z,explore\n" * 40_000
    response = client.post(
        "/logs/upload",
        data={"csrf_token": token, "file": (io.BytesIO(big), "big.csv")},
        content_type="multipart/form-data",
    )
    assert response.status_code == 413
    assert "larger than the limit of 1 MB" in text(response)
    assert list(tmp_path.iterdir()) == []


def test_delete_removes_the_log_and_everything_built_from_it(
    client, thesis_csv, log_name, graph_counts
):
    before = graph_counts()
    token, _ = read_step(client, "robotic_data.csv", thesis_csv.read_bytes())
    ingest(client, token, {"name": log_name, "entity": ["robot"]})
    assert log_name in stored(client)
    page = client.get("/logs").get_data(as_text=True)
    assert f'data-log="{log_name}"' in page
    response = client.post("/logs/delete", data={"csrf_token": client.csrf, "name": log_name})
    assert response.status_code == 302
    assert log_name not in stored(client)
    assert graph_counts() == before
    again = client.post("/logs/delete", data={"csrf_token": client.csrf, "name": log_name})
    assert again.status_code == 400 and "There is no log named" in text(again)
    no_token = client.post("/logs/delete", data={"name": log_name})
    assert no_token.status_code == 400


@pytest.mark.slow
def test_progress_is_reported_while_a_large_log_is_written(client, thesis_csv, log_name):
    # 8 runs of the thesis log as one file: large enough to watch the events arrive.
    with thesis_csv.open() as stream:
        rows = list(csv.DictReader(stream))
    out = io.StringIO()
    writer = csv.DictWriter(out, [*rows[0], "case"])
    writer.writeheader()
    body = [
        {**row, "event_id": f"{run}_{row['event_id']}", "case": f"run_{run}"}
        for run in range(8)
        for row in rows
    ]
    writer.writerows(body)
    data = out.getvalue().encode()
    token, _ = read_step(client, "runs.csv", data)
    job, seen = ingest(client, token, {"name": log_name, "entity": ["robot"]})
    assert job["error"] is None and job["result"]["events"] == len(body)
    partial = [s for s in seen if s["stage"] == "writing events" and 0 < s["done"] < s["total"]]
    assert partial, [(s["stage"], s["done"]) for s in seen]
    assert all(s["total"] == len(body) for s in partial)
    done = [s["done"] for s in partial]
    assert done == sorted(done)


@pytest.fixture(scope="module")
def simulated_runs(tmp_path_factory) -> Path:
    """Two short runs of the agri scenario, recorded by the simulator as rosbag2 folders."""
    out = tmp_path_factory.mktemp("sim") / "agri"
    command = [sys.executable, "-m", "robotale", "simulate", "agri", "--runs", "2"]
    command += ["--weeds", "2", "--tractors", "2", "--out", str(out), "--workers", "0", "--quiet"]
    subprocess.run(command, check=True, capture_output=True)
    return out


def zipped_folder(folder: Path) -> bytes:
    buffer = io.BytesIO()
    with zipfile.ZipFile(buffer, "w", zipfile.ZIP_DEFLATED) as archive:
        for path in sorted(folder.rglob("*")):
            archive.write(path, Path("agri") / path.relative_to(folder))
    return buffer.getvalue()


def test_a_zipped_bag_folder_is_prepared_and_linked_to_its_mission(
    client, simulated_runs, log_name, web_settings
):
    from robotale.eventlog.prepare import prepare
    from robotale.sim import scenarios
    from robotale.webapp.model_store import sanitised

    expected = prepare(simulated_runs)
    token, page = read_step(client, "agri.zip", zipped_folder(simulated_runs))
    assert f"{len(expected)} events" in page
    assert 'data-column="battery"' in page and 'data-column="robot_type"' in page
    job, _ = ingest(client, token, {"name": log_name, "entity": ["robot", "msg_id"]})
    assert job["error"] is None and job["result"]["events"] == len(expected)
    assert stored(client)[log_name]["events"] == len(expected)
    assert list(web_settings.upload_dir.iterdir()) == []  # zip and unpacked folder are gone

    agri = (scenarios.FOLDER / "agri.bpmn").read_bytes()
    model_page = text(client.get(f"/model?log={log_name}"))
    model_id = re.search(r'data-model="(\w+)"', model_page).group(1)
    # stored and served re-serialised without web content (test_web_security.py)
    assert client.get(f"/api/models/{model_id}.bpmn").data == sanitised(agri)

    # the runs' sites are kept for the Mission page's map: the world's field, each run's weeds
    for case in ("run_0001", "run_0002"):
        site = client.get(f"/api/mission/{log_name}/{case}").json["site"]
        manifest = json.loads((simulated_runs / case / "robotale-run.json").read_text())
        assert site["source"] == "world" and site["field"] == [10, 10]
        assert [(o["x"], o["y"]) for o in site["objects"]] == [
            (o["x"], o["y"]) for o in manifest["setup"]["objects"]
        ]


def first_run(folder: Path) -> str:
    """The case of the run whose truth begins first (its first line: case and start), read
    with the standard library."""
    heads = []
    for truth in sorted(folder.glob("*/robotale-truth.jsonl")):
        with truth.open() as lines:
            head = json.loads(lines.readline())
        heads.append((head["start"], head["case"]))
    assert len(heads) == 2
    return min(heads)[1]


@pytest.mark.browser
@pytest.mark.slow
def test_an_uploaded_recording_opens_its_first_run_on_the_mission_page(
    page, simulated_runs, log_name, tmp_path
):
    from playwright.sync_api import expect  # only the browser tests need playwright

    archive = tmp_path / "agri.zip"
    archive.write_bytes(zipped_folder(simulated_runs))
    expected = first_run(simulated_runs)

    page.goto(page.base_url + "/logs")
    page.set_input_files("input[name=file]", str(archive))
    page.click("#upload-form button[type=submit]")
    expect(page.locator("#columns-form")).to_be_visible(timeout=120_000)
    page.fill("#log-name", log_name)
    page.click("#ingest")
    page.wait_for_url(re.compile(r"/mission\?"), timeout=180_000)
    query = page.url.split("?", 1)[1].split("&")
    assert f"log={log_name}" in query and f"case={expected}" in query
    mission = page.locator("#mission")
    expect(mission).to_have_attribute("data-case", expected)
    expect(mission).to_have_attribute("data-state", "shown", timeout=60_000)
    expect(page.locator("#run-picker")).to_have_value(expected)


def test_the_reading_is_shown_and_the_findings_are_ready_once_stored(
    client, app, web_settings, thesis_csv, log_name
):
    import pandas as pd

    from robotale.webapp.state import state

    token, page = read_step(client, "robotic_data.csv", thesis_csv.read_bytes(), case_gap="1h")
    days = pd.to_datetime(pd.read_csv(thesis_csv)["time"]).dt.date.nunique()
    assert "How the file was read" in page
    assert f"{days} cases" in page
    assert str(web_settings.upload_dir) not in page  # the user's file name, not our copy's
    computed = state(app).logs.computed
    job, _ = ingest(client, token, {"name": log_name, "entity": ["robot", "msg_id"]})
    assert job["error"] is None, job["error"]
    deadline = time.monotonic() + 300
    while not computed[(log_name, "findings")]:
        assert time.monotonic() < deadline, "the findings were not prepared after storing"
        time.sleep(0.1)  # prepared without anyone asking
    findings = client.get(f"/api/findings?log={log_name}").json
    assert findings["answers"][0]["facts"]["runs"] == days
    assert computed[(log_name, "findings")] == 1  # the visit read what storing prepared


def test_a_csv_of_only_a_byte_order_mark_is_one_sentence(client):
    response = upload(client, "bom.csv", "\ufeff".encode())
    assert response.status_code == 400
    assert "'bom.csv' holds nothing but a byte order mark: it has no header line." in text(response)


def test_a_log_of_several_days_without_cases_is_offered_a_split_into_runs(
    client, thesis_csv, log_name
):
    import pandas as pd

    raw = pd.read_csv(thesis_csv)
    times = pd.to_datetime(raw["time"], format="ISO8601").sort_values()
    runs = int((times.diff() >= pd.Timedelta("1h")).sum()) + 1  # counted here, by hand
    token, page = read_step(client, "robotic_data.csv", thesis_csv.read_bytes())
    assert "1 case (no case column: one case)" in page and "spans 5 days" in page
    offer = re.search(r'<form[^>]*id="split-form".*?</form>', page, re.S).group(0)
    assert f'action="/logs/upload/{token}/split"' in offer and 'value="1h"' in offer
    response = client.post(
        f"/logs/upload/{token}/split", data={"csrf_token": client.csrf, "case_gap": "1h"}
    )
    assert response.status_code == 302, text(response)
    job_id = re.search(r"\?job=(\w+)", response.location).group(1)
    assert wait(client, job_id)["error"] is None
    page = text(client.get(response.location))
    assert f"{runs} cases (a new case after every pause of 1h or more)" in page
    assert 'id="split-form"' not in page
    job, _ = ingest(client, token, {"name": log_name, "entity": ["robot", "msg_id"]})
    assert job["error"] is None, job["error"]
    performance = client.get(f"/api/perspectives/performance?log={log_name}").json
    assert performance["summary"]["cases"] == runs == 5
    # the nights (pauses of 1 h or more between runs) no longer count as waiting
    assert performance["summary"]["slowest_transition"] != "land -> takeoff (drone)"
    assert max(row["max"] for row in performance["tables"]["waiting"]) < 3600


def test_a_log_stored_with_robotale_ingest_is_ready_for_its_first_visit(
    client, app, thesis_csv, log_name, capsys
):
    import pandas as pd

    from robotale.cli import main
    from robotale.webapp.state import state

    assert main(["ingest", str(thesis_csv), "--log", log_name, "--case-gap", "1h"]) == 0
    assert "preparing the dashboard's findings" in capsys.readouterr().out
    days = pd.to_datetime(pd.read_csv(thesis_csv)["time"]).dt.date.nunique()
    findings = client.get(f"/api/findings?log={log_name}").json
    assert findings["answers"][0]["facts"]["runs"] == days
    computed = state(app).logs.computed
    assert computed[(log_name, "findings")] == 0  # read from what the ingest kept
    assert client.get(f"/api/timeline/runs?log={log_name}").status_code == 200
    assert computed[(log_name, "runs")] == 0


def test_an_upload_larger_than_neo4js_free_disk_is_refused_before_writing(
    client, thesis_csv, log_name, graph_counts, monkeypatch, web_settings
):
    import shutil
    from collections import namedtuple

    from robotale.ekg import disk_space

    before = graph_counts()
    token, _ = read_step(client, "robotic_data.csv", thesis_csv.read_bytes())
    # The session's Neo4j cannot be moved onto a small disk: its disk's free space is the one
    # fact replaced (the command's check is tested on a real small disk, test_neo4j_full_disk).
    usage = namedtuple("usage", "total used free")
    monkeypatch.setattr(
        disk_space.shutil, "disk_usage", lambda path: usage(10**9, 10**9 - 100_000, 100_000)
    )
    try:
        job, _ = ingest(client, token, {"name": log_name, "entity": ["robot"]})
    finally:
        monkeypatch.setattr(disk_space.shutil, "disk_usage", shutil.disk_usage)
    assert job["error"].startswith("Neo4j's data folder "), job["error"]
    assert "has 97.7 kB free and storing the log" in job["error"]
    assert f"{log_name!r} (3,648 events) needs about " in job["error"]
    assert graph_counts() == before
    assert log_name not in stored(client)
    assert list(web_settings.upload_dir.iterdir()) == []
