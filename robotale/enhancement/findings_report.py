"""The findings as one self-contained HTML page (with the timelines of the runs the evidence
points at) and as JSON, the same data ``robotale report`` prints."""

from __future__ import annotations

import html
import json
from pathlib import Path
from typing import Any

import pandas as pd

from robotale.discovery.graph import json_ready
from robotale.discovery.output import write_texts
from robotale.enhancement.findings import Answer, Findings
from robotale.enhancement.timeline import Timeline, case_timeline, timeline_figure


def findings_dict(findings: Findings, timelines: list[Timeline], title: str) -> dict[str, Any]:
    """The answers, and the counts of the timelines of the runs they point at."""
    return json_ready(
        {"title": title, **findings.to_dict(), "timelines": [t.counts() for t in timelines]}
    )


def timelines_of(findings: Findings, log: pd.DataFrame) -> list[Timeline]:
    """The timelines of the runs the answers point at."""
    return [case_timeline(log, case) for case in findings.timeline_cases()]


def findings_text(findings: Findings) -> str:
    """The answers as plain text: a question, then its sentences."""
    blocks = []
    for answer in findings.answers:
        lines = [answer.question] + [f"  {s}" for s in answer.sentences if s]
        blocks.append("\n".join(lines))
    return "\n\n".join(blocks)


def findings_html(findings: Findings, timelines: list[Timeline], title: str) -> str:
    """One page that works offline: plotly's script inlined once, before the first timeline."""
    answers = "".join(_answer_html(answer) for answer in findings.answers)
    figures = []
    for number, timeline in enumerate(timelines):
        plotted = timeline_figure(timeline).to_html(full_html=False, include_plotlyjs=number == 0)
        figures.append(f"<section id='{_anchor(timeline.case)}'>{plotted}</section>")
    shown = "<h2>Timelines</h2>" + "".join(figures) if figures else ""
    return (
        "<!DOCTYPE html><html><head><meta charset='utf-8'>"
        f"<title>{html.escape(title)}</title><style>{_STYLE}</style></head>"
        f"<body><h1>{html.escape(title)}</h1>{answers}{shown}</body></html>"
    )


def write_findings(
    findings: Findings,
    log: pd.DataFrame,
    *,
    html_path: Path | None = None,
    json_path: Path | None = None,
    title: str = "robotale findings",
) -> None:
    """Write the HTML page and/or JSON file; either both appear complete or neither does."""
    outputs = []
    timelines = timelines_of(findings, log) if html_path or json_path else []
    if html_path is not None:
        outputs.append((Path(html_path), findings_html(findings, timelines, title)))
    if json_path is not None:
        data = findings_dict(findings, timelines, title)
        outputs.append((Path(json_path), json.dumps(data, ensure_ascii=False, indent=1)))
    write_texts(outputs)


def _answer_html(answer: Answer) -> str:
    sentences = "".join(f"<li>{html.escape(s)}</li>" for s in answer.sentences if s)
    links = []
    for evidence in answer.evidence:
        label = html.escape(evidence["label"])
        if evidence["kind"] == "timeline":
            links.append(f"<a href='#{_anchor(evidence['case'])}'>timeline of {label}</a>")
        else:
            links.append(f"<span class='evidence'>{label}</span>")
    shown = f"<p class='evidence'>Evidence: {' · '.join(links)}</p>" if links else ""
    return (
        f"<section class='answer' id='{answer.key}'><h2>{html.escape(answer.question)}</h2>"
        f"<ul>{sentences}</ul>{shown}</section>"
    )


def _anchor(case: str) -> str:
    return "timeline-" + "".join(c if c.isalnum() else "-" for c in str(case))


_STYLE = """
body { font-family: Helvetica, Arial, sans-serif; margin: 2em; color: #222; max-width: 70em; }
section.answer { margin-bottom: 2em; }
section.answer li { margin: 0.3em 0; }
p.evidence { color: #555; font-size: 0.9em; }
"""
