"""The dashboard is built from its registries: the menu a page renders is the page registry's
entries in their order, every registered page answers, and the Perspectives page has a section
for every registered perspective, in the registry's page order."""

from __future__ import annotations

import re

from robotale.enhancement.registry import PERSPECTIVES, page_names
from robotale.webapp.page_registry import PAGES, menu

NAV = re.compile(r"<nav>(.*?)</nav>", re.S)
ENTRY = re.compile(r'<a href="([^"]+)" data-endpoint="([^"]+)"\s+class="[^"]*">([^<]+)</a>')


def test_the_rendered_menu_is_the_page_registry(app, client):
    html = client.get("/logs").get_data(as_text=True)
    entries = ENTRY.findall(NAV.search(html).group(1))
    assert [(endpoint, label) for _, endpoint, label in entries] == menu()
    labelled = [p for p in PAGES if p.label is not None]
    assert [label for _, _, label in entries] == [p.label for p in labelled]
    # the pages the dashboard's documentation lists, in its order
    pages = [
        "Logs",
        "Findings",
        "Discover",
        "Perspectives",
        "Timeline",
        "Compare",
        "Mission",
        "Model",
    ]
    assert [label for _, _, label in entries] == [*pages, "Cypher"]
    for href, _, _ in entries:  # each entry leads to a page that renders
        assert client.get(href).status_code == 200, href
    # the app's blueprints are the registry's, and nothing else
    assert set(app.blueprints) == {page.view.blueprint.name for page in PAGES}


def test_the_perspectives_page_has_every_registered_perspective(client):
    html = client.get("/perspectives").get_data(as_text=True)
    sections = re.findall(r'<article class="perspective" data-name="([^"]+)">', html)
    assert sections == list(page_names())
    assert sorted(sections) == sorted(kind.name for kind in PERSPECTIVES)
    assert sections[0] == "bottlenecks"  # the ranking leads the page
