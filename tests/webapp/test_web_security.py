"""The dashboard's HTTP defences, through the real app: the Host allow-list (DNS rebinding),
the headers on every response, cookies, no inline script in any page, and uploaded models that
can run no script, in headless Chromium too."""

from __future__ import annotations

import io
import re

import pytest
from lxml import etree, html

from robotale.webapp import create_app
from robotale.webapp.settings import WebSettings

PAGES = [
    "/findings",
    "/logs",
    "/discover",
    "/perspectives",
    "/timeline",
    "/mission",
    "/model",
    "/cypher",
]
XHTML = "http://www.w3.org/1999/xhtml"


def header_values(response) -> dict[str, str]:
    return {name.lower(): value for name, value in response.headers.items()}


# -- Host -----------------------------------------------------------------------------------


def test_a_foreign_host_reaches_no_page_and_no_console(client):
    assert client.get("/cypher", headers={"Host": "attacker.example"}).status_code == 403
    response = client.post(
        "/api/cypher",
        json={"query": "MATCH (l:Log) RETURN l.name AS name", "parameters": {}},
        headers={
            "Host": "attacker.example:5000",
            "Origin": "http://attacker.example:5000",
            "X-CSRFToken": client.csrf,
        },
    )
    assert response.status_code == 403
    assert "results" not in response.get_data(as_text=True)
    assert "attacker.example" in response.get_data(as_text=True)


@pytest.mark.parametrize("host", ["localhost", "localhost:5000", "127.0.0.1:8080", "[::1]:5000"])
def test_the_names_of_this_machine_are_served(client, host):
    assert client.get("/static/js/common.js", headers={"Host": host}).status_code == 200


def test_more_names_are_configured_for_docker_and_remote_use(web_settings, monkeypatch):
    monkeypatch.setenv("ROBOTALE_ALLOWED_HOSTS", "dash.example, Robots.Lab ")
    configured = WebSettings.from_env().allowed_hosts
    assert {"dash.example", "robots.lab", "localhost", "127.0.0.1", "::1"} == set(configured)
    app = create_app(web_settings, allowed_hosts=configured).test_client()
    for host, status in [("dash.example", 200), ("robots.lab:80", 200), ("127.0.0.1", 200)]:
        assert app.get("/static/js/common.js", headers={"Host": host}).status_code == status
    assert app.get("/static/js/common.js", headers={"Host": "evil.example"}).status_code == 403
    everyone = create_app(web_settings, allowed_hosts=("*",)).test_client()
    assert everyone.get("/static/js/common.js", headers={"Host": "any.example"}).status_code == 200


# -- headers and cookies --------------------------------------------------------------------


@pytest.mark.parametrize("path", [*PAGES, "/api/logs", "/static/js/common.js", "/nowhere"])
def test_every_response_carries_the_defences(client, path):
    headers = header_values(client.get(path))
    directives = headers["content-security-policy"].split(";")
    policy = dict(directive.strip().split(" ", 1) for directive in directives)
    assert policy["script-src"] == "'self'"  # no inline script, no eval, nothing from elsewhere
    assert policy["object-src"] == "'none'" and policy["frame-ancestors"] == "'none'"
    assert headers["x-frame-options"] == "DENY"
    assert headers["x-content-type-options"] == "nosniff"
    assert headers["referrer-policy"] == "no-referrer"


def test_the_session_cookie_is_same_site_strict(app):
    fresh = app.test_client()
    cookie = fresh.get("/cypher").headers.get("Set-Cookie", "")
    assert cookie.startswith("session=")
    assert "SameSite=Strict" in cookie and "HttpOnly" in cookie


@pytest.mark.parametrize("path", PAGES)
def test_pages_hold_no_inline_script(client, path):
    response = client.get(path)
    assert response.status_code == 200
    document = html.fromstring(response.get_data(as_text=True))
    for script in document.iter("script"):
        # A script is a file of the dashboard, or data the browser never runs.
        assert script.get("src") or script.get("type") == "application/json", html.tostring(script)
        if script.get("src"):
            assert script.get("src").startswith("/") and not script.text
    handlers = [
        (element.tag, name)
        for element in document.iter()
        if isinstance(element.tag, str)
        for name in element.attrib
        if name.lower().startswith("on")
    ]
    assert handlers == []
    assert "javascript:" not in response.get_data(as_text=True).lower()


# -- uploaded models ------------------------------------------------------------------------


@pytest.fixture
def hostile_model(fame_models) -> bytes:
    """The thesis' agri mission with a script in XHTML, a stylesheet instruction and a handler."""
    data = (fame_models / "fame-ros" / "agri.bpmn").read_text(encoding="utf-8")
    data = re.sub(
        r"(<bpmn:definitions[^>]*>)",
        r'<?xml-stylesheet type="text/xsl" href="/evil.xsl"?>\n\1'
        '<html:script xmlns:html="http://www.w3.org/1999/xhtml">window.modelScriptRan = 1;'
        "</html:script>"
        '<svg:svg xmlns:svg="http://www.w3.org/2000/svg" onload="window.modelScriptRan = 2"/>',
        data,
        count=1,
    )
    assert "html:script" in data
    return data.encode("utf-8")


def upload(client, data: bytes) -> str:
    response = client.post(
        "/model",
        data={"csrf_token": client.csrf, "model": (io.BytesIO(data), "hostile.bpmn")},
        content_type="multipart/form-data",
    )
    assert response.status_code == 302, response.get_data(as_text=True)[:300]
    return response.location.split("model=")[1]


def test_uploaded_models_are_stored_without_web_content(client, app, hostile_model, fame_models):
    from robotale.fame_runtime.parser import parse, parse_bytes
    from robotale.webapp.state import state

    model_id = upload(client, hostile_model)
    stored = state(app).models.get(model_id).path.read_bytes()
    root = etree.fromstring(stored)
    namespaces = {etree.QName(element).namespace for element in root.iter(etree.Element)}
    assert XHTML not in namespaces and "http://www.w3.org/2000/svg" not in namespaces
    assert b"modelScriptRan" not in stored and b"xml-stylesheet" not in stored
    # Everything BPMN of the mission is still there.
    original = parse(fame_models / "fame-ros" / "agri.bpmn")
    kept = parse_bytes(stored, "stored.bpmn")
    assert [sorted(node.id for node in process.walk()) for _, process in original.pools()] == [
        sorted(node.id for node in process.walk()) for _, process in kept.pools()
    ]


def test_a_stored_model_is_served_so_that_it_cannot_run(client, hostile_model):
    model_id = upload(client, hostile_model)
    response = client.get(f"/api/models/{model_id}.bpmn")
    headers = header_values(response)
    assert response.mimetype == "text/plain"
    assert headers["content-disposition"].startswith("attachment")
    assert "sandbox" in headers["content-security-policy"]
    assert headers["x-content-type-options"] == "nosniff"


@pytest.mark.browser
def test_opening_an_uploaded_model_runs_no_script(page, client, hostile_model):
    model_id = upload(client, hostile_model)
    page.goto(page.base_url + f"/model?model={model_id}")
    from playwright.sync_api import expect

    expect(page.locator("#canvas")).to_have_attribute("data-rendered", "1")
    assert page.evaluate("window.modelScriptRan") is None
    # Opened directly, the file is a download, not a document of the dashboard's origin.
    with page.expect_download() as download:
        page.evaluate(f"window.location.href = '/api/models/{model_id}.bpmn'")
    assert download.value.suggested_filename == f"{model_id}.bpmn"
    assert page.evaluate("window.modelScriptRan") is None


@pytest.mark.browser
def test_every_page_runs_under_the_policy(page):
    violations: list[str] = []
    page.on(
        "console",
        lambda message: (
            violations.append(message.text) if "Content Security Policy" in message.text else None
        ),
    )
    for path in PAGES:
        response = page.goto(page.base_url + path)
        assert "script-src 'self'" in response.headers["content-security-policy"]
        page.wait_for_load_state("networkidle")
    assert violations == []
