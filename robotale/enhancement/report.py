"""All perspectives of a log at once, and their report as one HTML page and/or JSON file."""

from __future__ import annotations

import html
import json
from collections.abc import Sequence
from pathlib import Path

import pandas as pd

from robotale.discovery.output import write_texts
from robotale.enhancement.context import LogAnalysis, analysis_of
from robotale.enhancement.registry import PERSPECTIVES
from robotale.enhancement.result import Perspective
from robotale.enhancement.spatial import Field
from robotale.thresholds import LOW_BATTERY_PERCENT


def all_perspectives(
    log: pd.DataFrame | LogAnalysis,
    *,
    activity: str | None = None,
    robot: str | None = None,
    field: Field | None = None,
    threshold: float = LOW_BATTERY_PERCENT,
    delay_threshold: float | None = None,
    only: Sequence[str] | None = None,
) -> dict[str, Perspective]:
    """Every perspective of :data:`~robotale.enhancement.registry.PERSPECTIVES` (or those
    named in ``only``), for the whole log or for one activity and/or robot; a message is
    delayed above ``delay_threshold`` seconds (else by the rule of
    :mod:`robotale.enhancement.delays`)."""
    focus = {"activity": activity, "robot": robot}
    options = {"field": field, "threshold": threshold, "delay_threshold": delay_threshold}
    analysis = analysis_of(log)  # instances, steps, cases and messages built once for all
    return {
        kind.name: kind.compute(analysis, **focus, **kind.taken(options))
        for kind in PERSPECTIVES
        if only is None or kind.name in only
    }


def report_json(perspectives: dict[str, Perspective]) -> str:
    return json.dumps({name: p.to_dict() for name, p in perspectives.items()}, ensure_ascii=False)


def report_html(perspectives: dict[str, Perspective], title: str = "robotale perspectives") -> str:
    """One self-contained page (plotly's script inlined once, so it works offline)."""
    sections = []
    script_included = False
    for name, perspective in perspectives.items():
        parts = [f"<h2>{html.escape(name.capitalize())}</h2>"]
        if not perspective.has_data:
            parts.append(f"<p class='empty'>{html.escape(perspective.message or '')}</p>")
        else:
            parts.append(_summary_list(perspective.summary))
        for figure in perspective.figures.values():
            parts.append(figure.to_html(full_html=False, include_plotlyjs=not script_included))
            script_included = True
        for table_name, table in perspective.tables.items():
            if not table.empty:
                parts.append(f"<h3>{html.escape(table_name.replace('_', ' '))}</h3>")
                parts.append(table.head(200).to_html(index=False, border=0, float_format="%.3f"))
        sections.append("<section>" + "\n".join(parts) + "</section>")
    return (
        "<!DOCTYPE html><html><head><meta charset='utf-8'>"
        f"<title>{html.escape(title)}</title><style>{_STYLE}</style></head>"
        f"<body><h1>{html.escape(title)}</h1>{''.join(sections)}</body></html>"
    )


def _summary_list(summary: dict) -> str:
    """The headline figures as a definition list (lists and nested figures left to the
    tables)."""
    items = []
    for key, value in summary.items():
        if isinstance(value, dict | list):
            continue
        shown = f"{value:.3g}" if isinstance(value, float) else str(value)
        items.append(f"<dt>{html.escape(key.replace('_', ' '))}</dt><dd>{html.escape(shown)}</dd>")
    return f"<dl class='summary'>{''.join(items)}</dl>"


def write_report(
    perspectives: dict[str, Perspective],
    *,
    html_path: Path | None = None,
    json_path: Path | None = None,
    title: str = "robotale perspectives",
) -> None:
    """Write the HTML page and/or JSON file; either both appear complete or neither does."""
    outputs = []
    if html_path is not None:
        outputs.append((Path(html_path), report_html(perspectives, title)))
    if json_path is not None:
        outputs.append((Path(json_path), report_json(perspectives)))
    write_texts(outputs)


_STYLE = """
body { font-family: Helvetica, Arial, sans-serif; margin: 2em; color: #222; }
section { margin-bottom: 3em; }
table { border-collapse: collapse; font-size: 0.85em; margin: 0.5em 0 1.5em; }
th, td { padding: 0.25em 0.6em; border-bottom: 1px solid #ddd; text-align: right; }
th { background: #f4f4f4; }
.empty { color: #888; font-style: italic; }
dl.summary { display: grid; grid-template-columns: max-content auto; gap: 0.2em 1em; }
dl.summary dt { color: #555; }
dl.summary dd { margin: 0; }
"""
