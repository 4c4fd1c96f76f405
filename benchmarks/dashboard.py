"""How long the dashboard's pages take to show a stored log, measured in the browser.

    python benchmarks/dashboard.py [--sizes 10000 100000] [--repeat 3]
                                   [--pages discover perspectives findings]
    python benchmarks/dashboard.py --cold [--sizes 10000 100000]
    python benchmarks/dashboard.py --clients 20 [--rounds 5]

Starts a private Neo4j (see ``ekg_build.py``), stores logs of the given sizes as the dashboard
stores an upload (entities robot and msg_id, classes by activity and by activity and robot),
serves the dashboard and opens ``/discover?log=...`` in headless Chromium (Debian's, driven by
Playwright). The time to first graph runs from the start of the navigation to the moment the
graph's layered layout is drawn (the page's ``robotale-graph-drawn`` mark): HTML, scripts, the
class graph (from the log's columnar copy) and cytoscape's layout. Targets: under 1 s for
10,000 events and under 3 s for 100,000.

The logs: the thesis' five runs repeated as further runs (the mission's real shape: 24
classes), and, as a stress test, ``ekg_build.py``'s random log (10 robots doing anything in
any order: 150 classes, thousands of edges, of which the page draws the 150 most frequent).
Each log is timed twice: *cold*, with the dashboard's memory and the log's kept results
emptied before every load (a log stored with ``--pages visit``: the class graph is computed
from the log's columnar copy), and *warm* (a later visit, or the first one after the
dashboard stored the log, which prepares the first view while it ingests). The baseline,
measured in the same run, is the cold page for the thesis' own log (3,648 events); the DFG
tab (the log's columnar copy, then pm4py) is timed too, for reference.

The Perspectives, Findings and Mission pages are timed on the thesis-runs logs: *Perspectives
first view drawn* runs to the page's ``robotale-perspectives-drawn`` mark (the sections whose
heading is in the 1400 x 900 window shown, their figures and the class graph drawn; the
sections below the fold are loaded after it and their figures drawn while the browser is
idle, until ``robotale-perspectives-all-drawn``, printed too; a 3D figure is drawn only when
scrolled into the window, which the benchmark does not do), *Findings first paint* to
``robotale-findings-shown``, the *Mission page* to ``robotale-mission-shown`` (the first
run's map, model and robots drawn at its start; its timeline and plot, below the window, are
drawn when scrolled to). A page visited before its log's pages were
prepared computes what it shows (Perspectives, Mission) or shows how far their preparation is
and then its results (Findings): a cold time includes that work. After each page the page's own
measures are printed: each section's request, each figure's drawing, plotly.js's bundles.
Cold: the dashboard's memory emptied and the results it keeps of the log removed (its
columnar copy is there, nothing is computed yet); warm: after the computation that storing a
log runs, in the dashboard and in ``robotale ingest`` alike, so the first visit after an
ingest is warm. Targets: under 1 s at 10,000 events and under 3 s at 100,000, warm. The
baseline of these is the warm Findings page of the thesis' own log.

Before each page's browser time, the dashboard's own time for the same first view is printed:
the page's HTML and the answers its first view waits for (``FIRST_VIEW``: Discover's class
graph, the Perspectives page's first section and its class graph, the Findings), asked one
after the other over HTTP without a browser, cold or warm as the browser's loads are, with
the dashboard's CPU time beside it: what is left of the browser's time is the browser's own
(scripts, layout, plotly's drawing), which shares the machine's cores with the dashboard.
Discover's cold loads have their kept results removed too (the class graph is computed from
the log's columnar copy, not read from Neo4j).

``--cold`` times every page cold only, judged by the targets (under 1 s at 10,000 events and
3 s at 100,000); warm pages are judged by 0.5 s. Beside each time: the dashboard's CPU time
for the load (this process: the server's threads) and the load average.

``--clients N`` measures the Cypher console under load instead: N clients at once, each
asking the console one of its examples (``cypher/ask_*``, on the thesis' log), then a query
that costs Neo4j nothing (``RETURN 1``: what is left is the console's own time, its workers
included) and loading the Discover page, in turn (A B C A B C), over HTTP; every console
answer is checked equal to the same query run directly. Printed: the median and 99th
percentile of each, and of each example, the examples' ratio to Discover, errors and the load
average. Target: console median under 1 s at 20 clients, no error; the baseline is Discover.
The console keeps its answers while the database is unchanged (``robotale.ekg.answer_cache``):
each worker computes an example once, in the first round (the p99), and answers it from memory
after that; the expected answers are computed directly on the driver, apart from the console.
"""

from __future__ import annotations

import argparse
import contextlib
import logging
import os
import statistics
import sys
import tempfile
import time
from pathlib import Path

BENCHMARKS = Path(__file__).resolve().parent
sys.path.insert(0, str(BENCHMARKS))

from ekg_build import private_neo4j, synthetic_log  # noqa: E402

THESIS_CSV = BENCHMARKS.parent / "examples" / "thesis" / "robotic_data.csv"
TARGETS = {10_000: 1.0, 100_000: 3.0}
#: a page whose results were prepared, at any size
WARM_TARGET = 0.5
DRAWN = "performance.getEntriesByName('robotale-graph-drawn').length > 0"
#: the page and the mark that says it is on screen
PAGES = {
    "perspectives": ("Perspectives first view drawn", "robotale-perspectives-drawn"),
    "findings": ("Findings first paint", "robotale-findings-shown"),
    "mission": ("Mission page first state drawn", "robotale-mission-shown"),
}


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--sizes", type=int, nargs="+", default=[10_000, 100_000])
    parser.add_argument("--repeat", type=int, default=3, help="page loads per log (median)")
    parser.add_argument("--heap", default="2g", help="heap of the private Neo4j (2g)")
    parser.add_argument(
        "--pages", nargs="+", default=["discover", *PAGES], choices=["discover", *PAGES]
    )
    parser.add_argument(
        "--clients",
        type=int,
        default=0,
        help="instead of the pages: this many clients at once ask the console's examples and "
        "load Discover, over HTTP (console median and p99 beside Discover's)",
    )
    parser.add_argument("--rounds", type=int, default=5, help="requests of each kind per client")
    parser.add_argument(
        "--questions", nargs="+", metavar="NAME", help="with --clients: only these examples"
    )
    parser.add_argument(
        "--cold",
        action="store_true",
        help="time the pages cold only (no kept results, as for a log whose pages were not "
        "prepared yet) and judge them by the targets",
    )
    args = parser.parse_args()
    print(f"load average before: {os.getloadavg()[0]:.1f} on {os.cpu_count()} cores")
    if args.clients:
        with private_home(), private_neo4j(args.heap) as driver:
            name, _ = store(driver, "bench_thesis", thesis_log())
            return measure_clients(driver, name, args.clients, args.rounds, args.questions)
    with private_home(), private_neo4j(args.heap) as driver:
        logs = {"thesis": store(driver, "bench_thesis", thesis_log())}
        for size in args.sizes:
            logs[(size, "thesis runs")] = store(driver, f"bench_runs_{size}", thesis_runs(size))
            if "discover" in args.pages:
                logs[(size, "random")] = store(driver, f"bench_random_{size}", synthetic_log(size))
        measure_all(logs, args.repeat, args.pages, (True,) if args.cold else (True, False))
    print(f"load average after: {os.getloadavg()[0]:.1f}")
    return 0


@contextlib.contextmanager
def private_home():
    """A robotale home of the benchmark's own (the logs' copies and results go there); the
    cache of Neo4j's jars stays the user's."""
    from robotale.config import cache_dir

    saved = {key: os.environ.get(key) for key in ("ROBOTALE_HOME", "ROBOTALE_CACHE")}
    with tempfile.TemporaryDirectory(prefix="robotale-bench-home-") as scratch:
        os.environ["ROBOTALE_CACHE"] = str(cache_dir())
        os.environ["ROBOTALE_HOME"] = scratch
        try:
            yield Path(scratch)
        finally:
            for key, value in saved.items():
                if value is None:
                    os.environ.pop(key, None)
                else:
                    os.environ[key] = value


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
    """Store ``log`` as the dashboard's ingest does: the graph and the columnar copy."""
    from robotale.ekg.build import build_ekg
    from robotale.ekg.keys import built_keys

    entities = ["robot", "msg_id"]
    build_ekg(driver, log, name, entities=entities, aggregate=built_keys(entities),
              replace=True, progress=False)  # fmt: skip
    return name, len(log)


def measure_clients(
    driver, log: str, clients: int, rounds: int, only: list[str] | None = None
) -> int:
    """``clients`` threads, each asking the console an example, then :data:`TRIVIAL`, then
    loading the Discover page (A B C A B C), ``rounds`` times each; every console answer is
    checked equal to the same query run directly. Returns 1 when any request failed or
    differed."""
    import threading
    import time

    from robotale.ekg.readonly import run_read_only
    from robotale.webapp import create_app
    from robotale.webapp.serve import Dashboard

    questions = {k: v for k, v in _questions(log).items() if not only or k in only}
    expected = {
        name: [r.rows for r in run_read_only(driver, text, parameters, timeout=600)]
        for name, (text, parameters) in {**questions, TRIVIAL: (TRIVIAL, {})}.items()
    }
    times: dict[str, list[float]] = {"console": [], "trivial": [], "discover": []}
    per_question: dict[str, list[float]] = {}
    errors: list[str] = []
    print(f"{clients} clients, {rounds} rounds; load average before: {os.getloadavg()[0]:.1f}")
    with tempfile.TemporaryDirectory(prefix="robotale-bench-web-") as scratch:
        folder = Path(scratch)
        app = create_app(upload_dir=folder / "uploads", model_dir=folder / "models")
        logging.getLogger("werkzeug").setLevel(logging.WARNING)
        with Dashboard(app, port=0) as dashboard:

            def client(number: int) -> None:
                http = _Client(dashboard.url)
                names = list(questions)
                for turn in range(rounds):
                    name = names[(number + turn) % len(names)]
                    for kind, asked in (("console", name), ("trivial", TRIVIAL)):
                        text, parameters = questions.get(asked) or (asked, {})
                        started = time.monotonic()
                        body = {"query": text, "parameters": parameters}
                        status, answer = http.post_json("/api/cypher", body)
                        seconds = time.monotonic() - started
                        times[kind].append(seconds)
                        per_question.setdefault(asked, []).append(seconds)
                        rows = [r["rows"] for r in answer.get("results", [])]
                        if status != 200 or rows != expected[asked]:
                            errors.append(f"{kind} {asked}: {status} {str(answer)[:200]}")
                    started = time.monotonic()
                    status = http.get(f"/discover?log={log}")
                    times["discover"].append(time.monotonic() - started)
                    if status != 200:
                        errors.append(f"discover: {status}")

            threads = [threading.Thread(target=client, args=(n,)) for n in range(clients)]
            for thread in threads:
                thread.start()
            for thread in threads:
                thread.join()
    for kind, measured in times.items():
        print(f"{KINDS[kind]:>28}: {len(measured)} requests, median "
              f"{statistics.median(measured):.3f} s, p99 {_p99(measured):.3f} s")  # fmt: skip
    for name, measured in sorted(per_question.items()):
        print(f"{name:>28}: median {statistics.median(measured):.3f} s, "
              f"p99 {_p99(measured):.3f} s")  # fmt: skip
    console, discover = (statistics.median(times[kind]) for kind in ("console", "discover"))
    met = "met" if console < 1.0 else "MISSED"
    print(f"console median / Discover median: {console / discover:.2f}x; target console "
          f"median < 1 s: {met}")  # fmt: skip
    print(f"errors or differing answers: {len(errors)}")
    for error in errors[:5]:
        print(f"  {error}")
    print(f"load average after: {os.getloadavg()[0]:.1f}")
    return 1 if errors else 0


def _p99(measured: list[float]) -> float:
    ordered = sorted(measured)
    return ordered[min(len(ordered) - 1, int(0.99 * len(ordered)))]


#: a query that costs Neo4j nothing: what is left of its time is the console's own
TRIVIAL = "RETURN 1 AS one"
KINDS = {
    "console": "console (the examples)",
    "trivial": f"console ({TRIVIAL})",
    "discover": "Discover page",
}


def _questions(log: str) -> dict[str, tuple[str, dict]]:
    """The console's examples with parameters for the thesis log (two of its robots, its
    first run; the others at their defaults)."""
    from robotale.eventlog import schema
    from robotale.webapp.console import examples

    thesis = thesis_log()
    robots = [str(robot) for robot in thesis[schema.ROBOT].dropna().unique()[:2]]
    values = {"log": log, "robot": robots[0], "other": robots[1],
              "case": str(thesis[schema.CASE].iloc[0])}  # fmt: skip
    return {
        example.name: (example.text, {name: values.get(name) for name in example.parameters})
        for example in examples()
    }


class _Client:
    """One browser-like HTTP client: its own cookies and CSRF token."""

    def __init__(self, url: str) -> None:
        import http.cookiejar
        import re
        import urllib.request

        self.url = url
        self.opener = urllib.request.build_opener(
            urllib.request.HTTPCookieProcessor(http.cookiejar.CookieJar())
        )
        page = self.opener.open(f"{url}/cypher", timeout=600).read().decode()
        self.token = re.search(r'name="csrf-token" content="([^"]+)"', page).group(1)

    def get(self, path: str) -> int:
        import urllib.error

        try:
            with self.opener.open(f"{self.url}{path}", timeout=600) as response:
                response.read()
                return response.status
        except urllib.error.HTTPError as error:
            return error.code

    def get_json(self, path: str) -> tuple[int, object]:
        """The status and, for a JSON answer, its value (else None)."""
        import json
        import urllib.error

        try:
            with self.opener.open(f"{self.url}{path}", timeout=600) as response:
                data = response.read()
                kind = response.headers.get("Content-Type", "")
                return response.status, json.loads(data) if "json" in kind else None
        except urllib.error.HTTPError as error:
            return error.code, None

    def post_json(self, path: str, body: dict) -> tuple[int, dict]:
        import json
        import urllib.error
        import urllib.request

        request = urllib.request.Request(
            f"{self.url}{path}",
            data=json.dumps(body).encode(),
            headers={"Content-Type": "application/json", "X-CSRFToken": self.token},
        )
        try:
            with self.opener.open(request, timeout=600) as response:
                return response.status, json.loads(response.read())
        except urllib.error.HTTPError as error:
            return error.code, json.loads(error.read() or b"{}")


def measure_all(logs: dict, repeat: int, pages: list[str], modes=(True, False)) -> None:
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
            shown = [p for p in pages if p in PAGES]
            if shown:
                measure_pages(page, dashboard, logs, repeat, shown, baseline_name, modes)
            if "discover" not in pages:
                context.close()
                return
            baseline = first_graph(page, dashboard, baseline_name, repeat, cold=True)
            print(f"baseline: thesis log, {baseline_events:,} events: first graph in "
                  f"{baseline:.2f} s")  # fmt: skip
            for (size, kind), (name, events) in logs.items():
                target = TARGETS.get(size)
                for cold in modes:
                    server, server_cpu = server_seconds(dashboard, "discover", name, repeat, cold)
                    print(f"{events:>9,} events ({kind}, {'cold' if cold else 'warm'}): Discover "
                          f"first view answered by the dashboard (HTTP, no browser) in "
                          f"{server:.2f} s, CPU {server_cpu:.2f} s")  # fmt: skip
                    seconds = first_graph(page, dashboard, name, repeat, cold=cold)
                    verdict = f"target < {target:.0f} s: {'met' if seconds < target else 'MISSED'}"
                    print(f"{events:>9,} events ({kind}, {'cold' if cold else 'warm'}): first "
                          f"graph in {seconds:.2f} s ({seconds / baseline:.2f}x the baseline; "
                          f"{verdict if target else 'no target'})")  # fmt: skip
                dfg = first_graph(page, dashboard, name, 1, tab="#tab-dfg")
                print(f"{'':>9}  DFG tab (log's columnar copy, pm4py): {dfg:.2f} s "
                      f"({dfg / baseline:.2f}x the baseline)")  # fmt: skip
            context.close()


def measure_pages(
    page, dashboard, logs: dict, repeat: int, pages: list[str], thesis: str, modes=(True, False)
) -> None:
    """Perspectives fully drawn and Findings first paint, cold and warm (``modes``: True for
    cold), against the warm Findings page of the thesis' own log; the dashboard's CPU time
    (this process: the server's threads) beside each."""
    baseline, _ = page_seconds(page, dashboard, "findings", thesis, repeat, cold=False)
    print(f"baseline: thesis log, Findings first paint (warm) in {baseline:.2f} s")
    for (size, kind), (name, events) in logs.items():
        if kind != "thesis runs":
            continue
        target = TARGETS.get(size)
        for which in pages:
            for cold in modes:
                server, server_cpu = server_seconds(dashboard, which, name, repeat, cold)
                print(f"{events:>9,} events ({'cold' if cold else 'warm'}): {which} first view "
                      f"answered by the dashboard (HTTP, no browser) in {server:.2f} s, CPU "
                      f"{server_cpu:.2f} s (load average {os.getloadavg()[0]:.1f})")  # fmt: skip
                seconds, cpu = page_seconds(page, dashboard, which, name, repeat, cold)
                # cold: a log whose pages were not prepared yet (under 1 s at 10k, 3 s at
                # 100k); warm: after the preparation (under 0.5 s)
                limit = target if cold else WARM_TARGET
                verdict = f"target < {limit:g} s: {'met' if seconds < limit else 'MISSED'}"
                print(f"{events:>9,} events ({'cold' if cold else 'warm'}): {PAGES[which][0]} "
                      f"in {seconds:.2f} s, dashboard CPU {cpu:.2f} s per load "
                      f"({seconds / baseline:.2f}x the baseline; "
                      f"{verdict if target else 'no target'}; load average "
                      f"{os.getloadavg()[0]:.1f})")  # fmt: skip


#: the dashboard's answers the first view of each page waits for, after its HTML (``{log}``:
#: the log's name): Discover's class graph by activity and robot with every flow, the
#: Perspectives page's first section and the class graph beside it, the Findings, the Mission
#: page's run list, then its first run's head and its state at the start (``{case}``: the first
#: run the run list names)
FIRST_VIEW = {
    "discover": ("/discover", "/api/aggregation/steps", "/api/discover/ekg?by=robot"),
    "perspectives": (
        "/perspectives",
        "/api/perspectives/bottlenecks",
        "/api/discover/ekg?by=robot",
    ),
    "findings": ("/findings", "/api/findings"),
    "mission": (
        "/mission",
        "/api/timeline/runs",
        "/api/mission/{log}/{case}/head",
        "/api/mission/{log}/{case}/state?t=0",
    ),
}


def server_seconds(dashboard, which: str, log: str, repeat: int, cold: bool) -> tuple[float, float]:
    """The dashboard's own time for the first view of ``which``: median seconds from the first
    request for the page to the last answer it needs (:data:`FIRST_VIEW`, asked one after the
    other over HTTP, no browser), and the median CPU seconds of the dashboard meanwhile;
    ``cold`` as for :func:`page_seconds`."""
    from urllib.parse import quote

    client = _Client(dashboard.url)
    timings, spent = [], []
    for _ in range(repeat):
        empty(dashboard, log, cold)
        cpu, started = time.process_time(), time.perf_counter()
        case = ""
        for asked in FIRST_VIEW[which]:
            if "{" in asked:  # named in the path: the log and its first run
                path = asked.format(log=quote(log, safe=""), case=quote(case, safe=""))
            else:
                path = asked + ("&" if "?" in asked else "?") + f"log={quote(log)}"
            status, answer = client.get_json(path)
            if status != 200:
                raise SystemExit(f"{path} of {log} answered {status}")
            if asked == "/api/timeline/runs":
                case = str(answer["runs"][0]["case"])
        timings.append(time.perf_counter() - started)
        spent.append(time.process_time() - cpu)
    return statistics.median(timings), statistics.median(spent)


def empty(dashboard, log: str, cold: bool) -> None:
    """Before a cold load: the preparations the last load started in the dashboard ended, the
    dashboard's memory of ``log`` emptied and its kept results removed (its columnar copy
    stays: nothing is computed yet); before a warm one: its pages prepared as an ingest
    prepares them, then the memory emptied (a later visit)."""
    import shutil

    from robotale.ekg.columnar import log_build, results_folder
    from robotale.results.findings import prepare
    from robotale.webapp.state import state

    current = state(dashboard.app)
    driver = current.neo4j.driver()
    # a page visited before its log was prepared starts a preparation in the dashboard: done
    # before the next load, which would otherwise share the cores with it
    current.preparations.wait()
    current.logs.forget(log)
    if cold:
        # a request of the last load the browser left (a section below the fold) may still
        # be computing in the dashboard and write its result while the folder is removed
        folder = results_folder(log_build(driver, log))
        while folder.exists():
            shutil.rmtree(folder, ignore_errors=True)
    else:
        prepare(driver, current.logs, log)
        current.logs.forget(log)


def page_seconds(
    page, dashboard, which: str, log: str, repeat: int, cold: bool
) -> tuple[float, float]:
    """Median seconds from navigation start to the page's mark, and the dashboard's median CPU
    seconds meanwhile (this process); ``cold``: with the dashboard's memory and kept results
    of ``log`` emptied first, else after the ingest-time computation."""
    from browser import wait_for  # tests/webapp, put on the path by measure_all

    mark = PAGES[which][1]
    timings, spent = [], []
    for _ in range(repeat):
        empty(dashboard, log, cold)
        cpu = time.process_time()
        page.goto(f"{dashboard.url}/{which}?log={log}")
        wait_for(page, f"performance.getEntriesByName('{mark}').length > 0", timeout=600)
        spent.append(time.process_time() - cpu)
        timings.append(page.evaluate(f"performance.getEntriesByName('{mark}')[0].startTime") / 1000)
    answered = page.evaluate(_LAST_ANSWER) / 1000
    print(f"{'':>12}{which} of {log}: the last answer from the dashboard came at {answered:.2f} s")
    if which == "perspectives":
        everything = "performance.getEntriesByName('robotale-perspectives-all-drawn')"
        wait_for(page, f"{everything}.length > 0", timeout=600)
        below = page.evaluate(f"{everything}[0].startTime") / 1000
        print(f"{'':>12}every section and figure below the fold too, but a 3D one (drawn when "
              f"scrolled to; not timed above): drawn at {below:.2f} s")  # fmt: skip
    print_breakdown(page)
    return statistics.median(timings), statistics.median(spent)


def print_breakdown(page) -> None:
    """Where the last load's time went: when its HTML came and its scripts began (a page
    still busy drawing holds the next navigation until its task ends: the loads follow each
    other as a user's clicks do), the page's own measures (each section's request, each
    figure's drawing, plotly.js's load and parse) and the size of what it fetched."""
    answered, interactive = page.evaluate(_DOCUMENT)
    print(f"{'':>14}{'document answered, scripts begin':<34} {answered / 1000:6.2f} s → "
          f"{interactive / 1000:6.2f} s")  # fmt: skip
    for name, start, duration in page.evaluate(_MEASURES):
        print(f"{'':>14}{name:<34} {start / 1000:6.2f} s → {(start + duration) / 1000:6.2f} s")
    for name, size in page.evaluate(_SIZES):
        print(f"{'':>14}{name:<34} {size / 1e6:6.2f} MB")


#: when the page's HTML was answered and when its scripts began to run (domInteractive)
_DOCUMENT = (
    "[performance.getEntriesByType('navigation')[0].responseEnd,"
    " performance.getEntriesByType('navigation')[0].domInteractive]"
)
#: the page's measures, in the order they started
_MEASURES = (
    "performance.getEntriesByType('measure').filter((m) => m.name.startsWith('robotale-'))"
    ".sort((a, b) => a.startTime - b.startTime)"
    ".map((m) => [m.name.slice(9), m.startTime, m.duration])"
)
#: the size of every script and answer the page fetched (decoded)
_SIZES = (
    "performance.getEntriesByType('resource').filter((r) => r.decodedBodySize > 100000)"
    ".map((r) => [new URL(r.name).pathname, r.decodedBodySize])"
)


#: when the page's last request to /api/ was answered (what is left is the browser's drawing)
_LAST_ANSWER = (
    "Math.max(0, ...performance.getEntriesByType('resource')"
    ".filter((r) => r.name.includes('/api/')).map((r) => r.responseEnd))"
)


def first_graph(
    page, dashboard, log: str, repeat: int, tab: str | None = None, cold: bool = False
) -> float:
    """Median seconds from navigation start to the drawn graph (of the DFG tab, if ``tab``);
    ``cold``: with the dashboard's caches of this log emptied first."""
    from browser import wait_for  # tests/webapp, put on the path by measure_all

    url = dashboard.url
    timings = []
    for _ in range(repeat):
        if cold:
            empty(dashboard, log, cold=True)
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
