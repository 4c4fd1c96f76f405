"""The Compare page: what changed between two stored logs (two batches of runs), in plain
sentences first, then the changes, variants and bottlenecks as tables."""

from __future__ import annotations

from typing import Any

import pandas as pd
from flask import Blueprint, render_template, request

from robotale.enhancement.compare import TIMED, Comparison, compare_logs
from robotale.webapp import pages
from robotale.webapp.state import driver, state

blueprint = Blueprint("compare", __name__)

#: the changes table's columns, as the page heads them
CHANGE_COLUMNS = {
    "measure": "measure",
    "subject": "what",
    "who": "robot",
    "a": "A (mean)",
    "b": "B (mean)",
    "relative": "change",
    "q_value": "p (adjusted)",
    "ranked": "ranked",
}
VARIANT_COLUMNS = {"variant": "variant", "runs_a": "runs of A", "runs_b": "runs of B", "status": ""}
#: the figures' units of the measures of where the robots worked
UNITS = {"distance travelled": "metres per run", "region area": "square metres"}
#: how many changes the page draws as figures: the runs' durations, then the first changes
FIGURES = 6


@blueprint.get("/compare")
def page():
    first, second = request.args.get("a", ""), request.args.get("b", "")
    shown: dict[str, Any] = {}
    if first and second:
        logs = state().logs
        comparison = compare_logs(
            logs.frame(driver(), first), logs.frame(driver(), second), names=("A", "B")
        )
        shown = {
            "sentences": comparison.sentences,
            "changes": _rows(comparison.changes, CHANGE_COLUMNS),
            "variants": _rows(comparison.variants, VARIANT_COLUMNS),
            "figures": figures(comparison),
        }
    return render_template(
        "compare.html",
        first=first,
        second=second,
        change_heads=list(CHANGE_COLUMNS.values()),
        variant_heads=list(VARIANT_COLUMNS.values()),
        **shown,
        **pages.context("compare.page"),
    )


def figures(comparison: Comparison) -> list[dict[str, Any]]:
    """Plotly figures of the runs' durations and of the first tested changes after it: each
    batch's values, one per run, as a box with every run's point, so a shift carried by a few
    runs shows as well as one of the whole spread."""
    changes = comparison.changes
    tested = changes[changes["q_value"].notna() & (changes["measure"] != "run duration")]
    shown = [("run duration", "runs", "")]
    shown += list(tested[["measure", "subject", "who"]].itertuples(index=False, name=None))
    values = comparison.per_run
    drawn = []
    for measure, subject, who in shown[:FIGURES]:
        mine = values[
            (values["measure"] == measure) & (values["subject"] == subject) & (values["who"] == who)
        ]
        if mine.empty:
            continue
        drawn.append(_figure(measure, subject, who, mine, comparison.names))
    return drawn


def _figure(
    measure: str, subject: str, who: str, values: pd.DataFrame, names: tuple[str, str]
) -> dict[str, Any]:
    title = measure if measure == "run duration" else f"{measure}: {subject}"
    if who:
        title += f" ({who})"
    data = []
    for side, name in enumerate(names):
        part = values[values["side"] == side]
        data.append(
            {
                "type": "box",
                "name": name,
                "y": part["value"].astype(float).tolist(),
                "text": part["run"].astype(str).tolist(),
                "boxpoints": "all",
                "jitter": 0.4,
                "pointpos": 0,
                "hovertemplate": "run %{text}: %{y}<extra></extra>",
            }
        )
    # a frequency's share is counted in seconds, its values are counts
    counted = measure.endswith("frequency") or measure in ("message resends", "encounters")
    timed = measure in TIMED or measure == "message latency"
    unit = "times per run" if counted else "seconds" if timed else UNITS.get(measure, measure)
    layout = {"title": {"text": title}, "showlegend": False, "yaxis": {"title": {"text": unit}}}
    return {"data": data, "layout": layout, "measure": measure, "subject": subject, "who": who}


def _rows(table: pd.DataFrame, columns: dict[str, str]) -> list[list[str]]:
    """The table's cells as text, in the order of ``columns``."""
    return [
        [_cell(name, value) for name, value in row.items()]
        for row in table[list(columns)].to_dict("records")
    ]


def _cell(name: str, value: Any) -> str:
    if value is None or (not isinstance(value, str) and pd.isna(value)):
        return ""
    if name == "relative":
        return f"{value:+.0%}"
    if name == "q_value":
        return "< 0.001" if value < 0.001 else f"{value:.3f}"
    if isinstance(value, bool):
        return "yes" if value else ""
    if isinstance(value, float):
        return f"{value:.3g}"
    return str(value)
