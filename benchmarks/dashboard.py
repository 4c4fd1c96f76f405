"""How long the Discover page takes to show its first graph, measured in the browser.

    python benchmarks/dashboard.py [--sizes 10000 100000] [--repeat 3]

Starts a private Neo4j (see ``ekg_build.py``), stores logs of the given sizes as the dashboard
stores an upload (entities robot and msg_id, classes by activity and by activity and robot),
serves the dashboard and opens ``/discover?log=...`` in headless Chromium (Debian's, driven by
Playwright). The time to first graph runs from the start of the navigation to the moment the
graph's layered layout is drawn (the page's ``robotale-graph-drawn`` mark): HTML, scripts, the
class graph from Neo4j and cytoscape's layout. Targets: under 1 s for 10,000 events and under
3 s for 100,000.

The logs: the thesis' five runs repeated as further runs (the mission's real shape: 24
classes), and, as a stress test, ``ekg_build.py``'s random log (10 robots doing anything in
any order: 150 classes, thousands of edges, of which the page draws the 150 most frequent).
Each log is timed twice: *cold*, with the dashboard's caches emptied before every load (a log
stored by the command line, or the first visit after a restart: the class graph is queried
from Neo4j), and *warm* (a later visit, or the first one after the dashboard stored the log,
which prepares the first view while it ingests). The baseline, measured in the same run, is
the cold page for the thesis' own log (3,648 events); the DFG tab (the log read back from
Neo4j, then pm4py) is timed too, for reference.
"""

from __future__ import annotations

import argparse
import logging
import statistics
import sys
import tempfile
from pathlib import Path

BENCHMARKS = Path(__file__).resolve().parent
sys.path.insert(0, str(BENCHMARKS))

from ekg_build import private_neo4j, synthetic_log  # noqa: E402

THESIS_CSV = BENCHMARKS.parent / "examples" / "thesis" / "robotic_data.csv"
TARGETS = {10_000: 1.0, 100_000: 3.0}
DRAWN = "performance.getEntriesByName('robotale-graph-drawn').length > 0"


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--sizes", type=int, nargs="+", default=[10_000, 100_000])
    parser.add_argument("--repeat", type=int, default=3, help="page loads per log (median)")
    parser.add_argument("--heap", default="2g", help="heap of the private Neo4j (2g)")
    args = parser.parse_args()
    with private_neo4j(args.heap) as driver:
        logs = {"thesis": store(driver, "bench_thesis", thesis_log())}
        for size in args.sizes:
            logs[(size, "thesis runs")] = store(driver, f"bench_runs_{size}", thesis_runs(size))
            logs[(size, "random")] = store(driver, f"bench_random_{size}", synthetic_log(size))
        measure_all(logs, args.repeat)
    return 0


def thesis_log():
    from robotale.eventlog.readers import read_log

    return read_log(THESIS_CSV)


def thesis_runs(events: int):
    """The thesis log's runs repeated, a week apart, until the log has ``events`` events."""
    import pandas as pd

    from robotale.eventlog import schema

    thesis = thesis_log()
    copies = []
    for copy in range(-(-events // len(thesis))):
        run = thesis.copy()
        run[schema.CASE] = f"run_{copy}"
        run[schema.TIMESTAMP] = run[schema.TIMESTAMP] + pd.Timedelta(weeks=copy)
        run[schema.MSG_ID] = (f"{copy}_" + run[schema.MSG_ID].astype("string")).where(
            run[schema.MSG_ID].notna()
        )
        run[schema.EVENT_ID] = f"{copy}_" + run[schema.EVENT_ID].astype(str)
        copies.append(run)
    return pd.concat(copies, ignore_index=True).head(events)


def store(driver, name: str, log) -> tuple[str, int]:
    from robotale.ekg.build import build_ekg
    from robotale.ekg.keys import built_keys

    entities = ["robot", "msg_id"]
    build_ekg(driver, log, name, entities=entities, aggregate=built_keys(entities),
              replace=True, progress=False)  # fmt: skip
    return name, len(log)


def measure_all(logs: dict, repeat: int) -> None:
    from playwright.sync_api import sync_playwright

    from robotale.webapp import create_app
    from robotale.webapp.serve import Dashboard

    # The headless Chromium of the browser tests: one place drives it for both.
    sys.path.insert(0, str(Path(__file__).resolve().parent.parent / "tests" / "webapp"))
    from browser import launch

    with tempfile.TemporaryDirectory(prefix="robotale-bench-web-") as scratch:
        folder = Path(scratch)
        app = create_app(upload_dir=folder / "uploads", model_dir=folder / "models")
        logging.getLogger("werkzeug").setLevel(logging.WARNING)  # one line per request otherwise
        with Dashboard(app, port=0) as dashboard, sync_playwright() as playwright:
            context = launch(playwright, folder / "profile")
            page = context.new_page()
            page.goto(f"{dashboard.url}/cypher")  # warm the browser's cache of the scripts
            baseline_name, baseline_events = logs.pop("thesis")
            baseline = first_graph(page, dashboard, baseline_name, repeat, cold=True)
            print(f"baseline: thesis log, {baseline_events:,} events: first graph in "
                  f"{baseline:.2f} s")  # fmt: skip
            for (size, kind), (name, events) in logs.items():
                target = TARGETS.get(size)
                for cold in (True, False):
                    seconds = first_graph(page, dashboard, name, repeat, cold=cold)
                    verdict = f"target < {target:.0f} s: {'met' if seconds < target else 'MISSED'}"
                    print(f"{events:>9,} events ({kind}, {'cold' if cold else 'warm'}): first "
                          f"graph in {seconds:.2f} s ({seconds / baseline:.2f}x the baseline; "
                          f"{verdict if target else 'no target'})")  # fmt: skip
                dfg = first_graph(page, dashboard, name, 1, tab="#tab-dfg")
                print(f"{'':>9}  DFG tab (log read from Neo4j, pm4py): {dfg:.2f} s "
                      f"({dfg / baseline:.2f}x the baseline)")  # fmt: skip
            context.close()


def first_graph(
    page, dashboard, log: str, repeat: int, tab: str | None = None, cold: bool = False
) -> float:
    """Median seconds from navigation start to the drawn graph (of the DFG tab, if ``tab``);
    ``cold``: with the dashboard's caches of this log emptied first."""
    from browser import wait_for  # tests/webapp, put on the path by measure_all

    from robotale.webapp.state import state

    url = dashboard.url
    timings = []
    for _ in range(repeat):
        if cold:
            state(dashboard.app).logs.forget(log)
        page.goto(f"{url}/discover?log={log}")
        wait_for(page, DRAWN, timeout=300)
        if tab is None:
            timings.append(page.evaluate(_MARK) / 1000)
            continue
        page.evaluate("performance.clearMarks('robotale-graph-drawn')")
        started = page.evaluate("performance.now()")
        page.click(tab)
        wait_for(page, DRAWN, timeout=300)
        timings.append((page.evaluate(_MARK) - started) / 1000)
    return statistics.median(timings)


_MARK = "performance.getEntriesByName('robotale-graph-drawn')[0].startTime"


if __name__ == "__main__":
    sys.exit(main())
