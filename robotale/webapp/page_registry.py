"""Every page of the dashboard, once: its blueprint, its menu entry and their order.

The app registers the blueprints in this order and the menu (``base.html``) lists the entries
that have a label in the same order, so a new page is one :class:`Page` here (and its view
module with a ``page`` endpoint).
"""

from __future__ import annotations

from dataclasses import dataclass
from types import ModuleType

from robotale.webapp.views import (
    aggregation,
    assets,
    compare,
    console,
    discover,
    findings,
    logs,
    mission,
    model,
    perspectives,
    preparation,
    timeline,
)


@dataclass(frozen=True)
class Page:
    """A view module (its ``blueprint``) and, when it is a page of the menu, its label."""

    view: ModuleType
    label: str | None = None

    @property
    def endpoint(self) -> str:
        """The menu entry's endpoint: the blueprint's ``page`` view."""
        return f"{self.view.blueprint.name}.page"


#: every blueprint in the order it is registered; those with a label are the menu, in order
PAGES: tuple[Page, ...] = (
    Page(assets),
    Page(logs, "Logs"),
    Page(findings, "Findings"),
    Page(discover, "Discover"),
    Page(aggregation),  # the Discover page's aggregation requests
    Page(preparation),  # how far a log's pages are prepared
    Page(perspectives, "Perspectives"),
    Page(timeline, "Timeline"),
    Page(compare, "Compare"),
    Page(mission, "Mission"),
    Page(model, "Model"),
    Page(console, "Cypher"),
)


def menu() -> list[tuple[str, str]]:
    """The menu's entries: (endpoint, label), in order."""
    return [(page.endpoint, page.label) for page in PAGES if page.label is not None]
