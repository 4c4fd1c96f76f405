"""The Timeline's battery on its own axis and one colour per activity, the same on every page,
on small logs counted by hand."""

from __future__ import annotations

from robotale.enhancement.colours import PALETTE
from robotale.enhancement.spatial import spatial_perspective
from robotale.enhancement.timeline import case_timeline, timeline_figure


def _many(events, activities: int, runs: int = 2):
    """``runs`` runs of one robot doing ``activities`` activities one after another (a00 ...),
    2 s each, with a battery level at every start and a position."""
    rows = []
    for run in range(runs):
        for n in range(activities):
            name = f"a{n:02d}"
            t = 100 * run + 2 * n
            level = 90.0 - n
            common = {"case": str(run), "robot": "r1", "activity": name, "x": float(n), "y": 0.0}
            rows.append(common | {"lifecycle": "start", "t": t, "battery": level})
            rows.append(common | {"lifecycle": "complete", "t": t + 1, "battery": level - 0.5})
    return events(*rows)


def test_thirty_activities_have_thirty_colours(events):
    log = _many(events, 30)
    figure = timeline_figure(case_timeline(log, "0"))
    bars = {trace.name: trace.marker.color for trace in figure.data if trace.type == "bar"}
    assert len(bars) == 30 and len(set(bars.values())) == 30
    assert len(PALETTE) >= 30


def test_the_same_activity_has_the_same_colour_on_every_page(events):
    log = _many(events, 12)
    # run 1 without its first five activities: the others keep their colours
    later = log[~((log["case:concept:name"] == "1") & (log["concept:name"] < "a05"))]
    first = timeline_figure(case_timeline(later, "0"))
    second = timeline_figure(case_timeline(later, "1"))
    scatter = spatial_perspective(later).figure
    colour = {t.name: t.marker.color for t in first.data if t.type == "bar"}
    for figure in (second, scatter):
        for trace in figure.data:
            if trace.name in colour:
                assert trace.marker.color == colour[trace.name], trace.name
    assert {t.name for t in second.data if t.type == "bar"} == {f"a{n:02d}" for n in range(5, 12)}


def test_the_battery_has_its_own_axis_below_the_lanes(events):
    """The levels (84.5-90 %) are drawn against a 0-105 % axis that shares no height with the
    robots' lanes, so no level reads as a lane."""
    figure = timeline_figure(case_timeline(_many(events, 6), "0"))
    layout = figure.layout
    lanes, battery = list(layout.yaxis.domain), list(layout.yaxis2.domain)
    assert battery[1] < lanes[0]  # below, apart
    assert layout.yaxis2.overlaying is None and list(layout.yaxis2.range) == [0, 105]
    lines = [t for t in figure.data if t.type == "scatter" and t.name == "battery r1"]
    assert len(lines) == 1 and lines[0].yaxis == "y2"
    assert min(lines[0].y) == 84.5 and max(lines[0].y) == 90.0
