"""The Model page's verification: the findings of ``robotale fame verify`` on a stored model,
and the elements of a chosen counterexample outlined on the drawing (thesis FAME models)."""

from __future__ import annotations

import io

import pytest
from browser import upload_model
from playwright.sync_api import expect

from robotale.fame_runtime.parser import parse_bytes
from robotale.fame_runtime.verify import verify
from robotale.webapp.model_store import sanitised


def upload(client, path) -> str:
    response = client.post(
        "/model",
        data={"csrf_token": client.csrf, "model": (io.BytesIO(path.read_bytes()), path.name)},
        content_type="multipart/form-data",
    )
    assert response.status_code == 302
    return response.location.split("model=")[1]


def test_the_api_gives_the_findings_the_command_gives(client, fame_models):
    goto = fame_models / "fame-ros" / "GoTo.bpmn"
    model_id = upload(client, goto)
    data = client.get(f"/api/models/{model_id}/verify").get_json()
    # the page draws the model without script bodies (web content), but verifies it as
    # uploaded: the findings are the command's on the authors' file, scripts read
    expected = verify(parse_bytes(goto.read_bytes(), f"{model_id}.bpmn"))
    assert [(f["kind"], f["sentence"]) for f in data["findings"]] == [
        (f.kind, f.sentence) for f in expected.findings
    ]
    loop = data["findings"][0]
    assert loop["kind"] == "no_exit" and loop["elements"][0] == "Gateway_0mn0474"
    assert (
        "it reads reached = false, set by Activity_1gbttx6 (Check Position) in the same step"
        in loop["sentence"]
    )
    # what the page draws still has no script
    drawn = client.get(f"/api/models/{model_id}.bpmn").data
    assert drawn == sanitised(goto.read_bytes()) and b"reached = false" not in drawn
    assert b"reached = false" in goto.read_bytes()
    assert [t["activity"] for t in loop["trace"]][-2:] == ["check_position", "check_position"]
    assert data["file"] == f"{model_id}.bpmn"  # no path of the server
    assert client.get("/api/models/0000000000000000/verify").status_code == 400


@pytest.mark.browser
def test_choosing_a_finding_outlines_its_counterexample(page, fame_models):
    goto = fame_models / "fame-ros" / "GoTo.bpmn"
    upload_model(page, goto)
    page.click("#verify")
    finding = page.locator("#verify-list li[data-kind=no_exit]")
    expect(finding).to_contain_text("Gateway_0mn0474 (destination reached?) never takes")
    finding.click()
    elements = verify(parse_bytes(goto.read_bytes(), "GoTo.bpmn")).findings[0].elements
    expect(page.locator("#canvas")).to_have_attribute("data-counterexample", " ".join(elements))
    outlined = page.eval_on_selector_all(
        ".djs-element.counterexample", "els => els.map(e => e.dataset.elementId)"
    )
    assert sorted(outlined) == sorted(elements) and "Gateway_0mn0474" in outlined
    stroke = page.eval_on_selector(
        "[data-element-id=Gateway_0mn0474] .djs-visual > :first-child",
        "e => getComputedStyle(e).stroke",
    )
    assert stroke == "rgb(130, 80, 223)"
    expect(page.locator("#verify-trace table")).to_contain_text("check_position")
