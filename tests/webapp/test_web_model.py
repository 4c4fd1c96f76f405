"""The Model page's store of BPMN collaborations and its endpoints (thesis FAME models)."""

from __future__ import annotations

import io

import pytest

from robotale.errors import InputError
from robotale.webapp.model_store import ModelStore, sanitised


@pytest.fixture
def agri(fame_models):
    return fame_models / "fame-ros" / "agri.bpmn"


def test_models_are_stored_once_by_content_and_linked_to_logs(tmp_path, agri):
    store = ModelStore(tmp_path)
    first = store.add(agri.read_bytes(), "agri.bpmn")
    again = store.add(agri.read_bytes(), "copy of agri.bpmn")
    assert first.id == again.id and len(first.id) == 16
    assert first.pools == ["Tractor", "Drone"]
    assert [m.id for m in store.all()] == [first.id]
    # stored as written again without web content (see test_web_security_models.py)
    assert store.get(first.id).path.read_bytes() == sanitised(agri.read_bytes())
    assert store.linked("agri") is None
    store.link("agri", first.id)
    assert store.linked("agri").id == first.id
    assert sorted(p.name for p in tmp_path.iterdir()) == sorted(
        [f"{first.id}.bpmn", f"{first.id}.json", "links.json", "originals"]
    )
    # the upload itself, kept for the verification (it reads the scripts), never served
    assert store.get(first.id).original == tmp_path / "originals" / f"{first.id}.bpmn"
    assert store.get(first.id).original.read_bytes() == agri.read_bytes()


@pytest.mark.parametrize(
    ("name", "data", "message"),
    [
        ("mission.txt", b"<definitions/>", "is not a .bpmn file"),
        ("broken.bpmn", b"<definitions><process id='p'>", "broken.bpmn"),
    ],
)
def test_files_the_parser_refuses_are_not_stored(tmp_path, name, data, message):
    with pytest.raises(InputError, match=message):
        ModelStore(tmp_path).add(data, name)
    assert not tmp_path.exists() or list(tmp_path.iterdir()) == []


def test_ids_that_are_not_ours_find_nothing(tmp_path):
    for model_id in ("../../etc/passwd", "", "0" * 16):
        with pytest.raises(InputError, match="no stored model"):
            ModelStore(tmp_path).get(model_id)


def test_upload_then_page_then_xml(client, agri):
    response = client.post(
        "/model",
        data={
            "csrf_token": client.csrf,
            "log": "agri-runs",
            "model": (io.BytesIO(agri.read_bytes()), "agri.bpmn"),
        },
        content_type="multipart/form-data",
    )
    assert response.status_code == 302
    model_id = response.location.split("model=")[1]
    assert "log=agri-runs" in response.location
    page = client.get("/model?log=agri-runs").get_data(as_text=True)
    assert f'data-model="{model_id}"' in page  # the log's own model is chosen
    assert "agri.bpmn (Tractor, Drone)" in page
    xml = client.get(f"/api/models/{model_id}.bpmn")
    # plain text, so that a browser opening it runs nothing (see test_web_security_models.py)
    assert xml.mimetype == "text/plain" and xml.data == sanitised(agri.read_bytes())
    assert client.get("/api/models/0000000000000000.bpmn").status_code == 400


def test_upload_without_token_or_file_is_refused(client, agri):
    no_token = client.post(
        "/model",
        data={"model": (io.BytesIO(agri.read_bytes()), "agri.bpmn")},
        content_type="multipart/form-data",
    )
    assert no_token.status_code == 400
    no_file = client.post("/model", data={"csrf_token": client.csrf})
    assert no_file.status_code == 400 and "Choose a .bpmn file" in no_file.get_data(as_text=True)


def test_the_shipped_missions_are_offered_and_found_by_the_log_robots(tmp_path):
    from robotale.sim import scenarios

    store = ModelStore(tmp_path)
    shipped = store.add_shipped()
    assert sorted(m.name for m in shipped) == sorted(
        p.name for p in scenarios.FOLDER.glob("*.bpmn")
    )
    by_name = {m.name: m for m in store.all()}
    assert store.matching(["drone", "tractor_1", "tractor_2"]).id == by_name["agri.bpmn"].id
    assert store.matching(["rex", "dingo"]).id == by_name["rexdingo.bpmn"].id
    assert store.matching(["ufo"]) is None
    assert store.add_shipped() == shipped  # stored once
    assert len(store.all()) == len(shipped)


def test_a_script_can_attach_the_mission_to_a_log(tmp_path, monkeypatch, agri):
    from robotale.webapp.model_store import attach_model

    monkeypatch.setenv("ROBOTALE_MODEL_DIR", str(tmp_path))
    stored = attach_model("agri-runs", agri)
    assert ModelStore(tmp_path).linked("agri-runs").id == stored.id
    assert stored.path.read_bytes() == sanitised(agri.read_bytes())
