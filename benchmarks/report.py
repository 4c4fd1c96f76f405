"""How long the whole findings report takes, against pm4py doing the same work, and how soon
the dashboard's Findings page shows it.

    python benchmarks/report.py [--sizes 10000 100000 1000000] [--stored 10000 100000 1000000]
                                [--page 10000 100000] [--repeat 3] [--runs 3]

The logs are the thesis' five runs repeated as further runs (the mission's real shape) until
they have the given number of events. For each size, in the same run:

- *pm4py's four functions*: ``discover_dfg``, ``discover_performance_dfg``, ``get_variants``
  and ``get_all_case_durations`` on the raw rows (each lifecycle row an event, nothing paired:
  less work than the report's, on what is in effect another log);
- *pm4py, the same work*: the parts of the report pm4py has functions for, done by them: its
  own pairing of starts with completions (event log, ``interval_lifecycle.to_interval``, back
  to a DataFrame), then service time per activity, each robot's frequency and performance DFG
  on the intervals with the start timestamp key, variants per case and per robot, case
  durations and robot spans, rework per activity (see ``discovery.py``); checked on the
  benchmark's own log to compute robotale's numbers, the check printed. pm4py has nothing for
  the rest of the report (the effect of each candidate on the runs, the waits split from the
  work, the robots' areas, battery, messages), which it therefore does not pay for;
- *findings*: ``robotale.enhancement.findings.find`` on that DataFrame (all five answers:
  variants, bottlenecks with their effect on the runs, robots' work, battery, messages);
  target: within 2x of pm4py's time for the same work. All three are the best of ``--runs``
  runs (3), so a busy moment of a shared machine weighs less, in wall-clock and in CPU time of
  the process (which leaves the other processes out); the load average is printed first;
- *report from a file*: ``robotale report LOG.csv --out --json`` as the command does it (read
  the CSV, the findings, the timelines, the HTML and JSON written);
- *report from a stored log*: the same with ``--log NAME`` (the log read back from Neo4j),
  for the ``--stored`` sizes, in a private Neo4j (see ``ekg_build.py``).

With ``--truth N`` (5), N generated missions (``robotale.sim.generate``, seeds 1..N, one
run each, simulated and prepared first, untimed) are checked against their ground truth as
``make verify-findings`` does (``tests/truth``: the oracle's answers from the truth file and
their comparison with robotale's messages, activities, durations, DFG and battery), and
the findings of the same log are timed beside it, interleaved, best of ``--runs``: the time
per mission of the truth check, and its ratio to the findings'. The check's message count is
checked equal to the findings'.

With ``--page`` sizes, the dashboard serves those stored logs and headless Chromium (Debian's,
driven by Playwright) opens ``/findings?log=...``: the first paint of the findings runs from
the start of the navigation to the page's ``robotale-findings-shown`` mark, cold (the
dashboard's caches of the log emptied first: a log stored by the command line) and warm (as
after the dashboard stored the log: it prepares the findings while storing). Targets: under
1 s at 10,000 events and under 3 s at 100,000.
"""

from __future__ import annotations

import argparse
import contextlib
import io
import logging
import os
import statistics
import sys
import tempfile
import time
import warnings
from pathlib import Path

BENCHMARKS = Path(__file__).resolve().parent
sys.path.insert(0, str(BENCHMARKS))

from dashboard import store, thesis_runs  # noqa: E402
from discovery import (  # noqa: E402
    best,
    pm4py_performance,
    pm4py_same_work,
    print_figures,
    print_ratios,
    same_numbers,
)
from ekg_build import private_neo4j  # noqa: E402

PAGE_TARGETS = {10_000: 1.0, 100_000: 3.0}
SHOWN = "performance.getEntriesByName('robotale-findings-shown').length > 0"
MARK = "performance.getEntriesByName('robotale-findings-shown')[0].startTime"


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--sizes", type=int, nargs="*", default=[10_000, 100_000, 1_000_000])
    parser.add_argument("--stored", type=int, nargs="*", default=[10_000, 100_000, 1_000_000])
    parser.add_argument("--page", type=int, nargs="*", default=[10_000, 100_000])
    parser.add_argument("--repeat", type=int, default=3, help="page loads per log (median)")
    parser.add_argument("--heap", default="2g", help="heap of the private Neo4j (2g)")
    parser.add_argument("--runs", type=int, default=3, help="runs of pm4py and findings (best)")
    parser.add_argument("--truth", type=int, default=5, help="generated missions checked (5)")
    args = parser.parse_args()
    warnings.simplefilter("ignore")
    warm_up()
    print("load average (1, 5, 15 min): " + ", ".join(f"{n:.1f}" for n in os.getloadavg()))
    with tempfile.TemporaryDirectory(prefix="robotale-bench-report-") as scratch:
        for size in args.sizes:
            measure_file(size, Path(scratch), args.runs)
        if args.truth:
            measure_truth(args.truth, Path(scratch), args.runs)
        if args.stored or args.page:
            with private_neo4j(args.heap) as driver:
                stored = {}
                for size in sorted(set(args.stored) | set(args.page)):
                    stored[size] = store(driver, f"bench_report_{size}", thesis_runs(size))[0]
                for size in args.stored:
                    measure_stored(size, stored[size], Path(scratch))
                if args.page:
                    measure_pages({size: stored[size] for size in args.page}, args.repeat)
    return 0


def warm_up() -> None:
    """Imports and first calls stay out of the figures."""
    from robotale.enhancement.findings import find

    small = thesis_runs(2_000)
    find(small)
    pm4py_performance(small)
    same_work(small)


def timed(function, *args, **kwargs) -> float:
    began = time.perf_counter()
    function(*args, **kwargs)
    return time.perf_counter() - began


def quietly(function, *args, **kwargs) -> None:
    """A command's printed findings and reading stay out of the benchmark's output."""
    with contextlib.redirect_stdout(io.StringIO()), contextlib.redirect_stderr(io.StringIO()):
        function(*args, **kwargs)


def measure_file(size: int, folder: Path, runs: int) -> None:
    from robotale.commands.report import report_command
    from robotale.enhancement.findings import find
    from robotale.eventlog.writers import write_csv

    log = thesis_runs(size)
    path = folder / f"runs_{size}.csv"
    write_csv(log, path)
    print(f"== {len(log):,} events, {log['case:concept:name'].nunique():,} runs")
    print("  check: " + same_numbers(log, pm4py_same_work(log, rework=True)))
    four, same = best(runs, pm4py_performance, log), best(runs, same_work, log)
    ours = best(runs, find, log)
    command = timed(
        quietly, report_command, path, out=folder / "report.html", json_out=folder / "r.json"
    )
    print_figures(
        [
            ("pm4py's four functions on the raw rows", four),
            ("pm4py, the same work", same),
            ("robotale findings (five answers)", ours),
        ]
    )
    print_ratios("findings", ours, same, four)
    print(f"  {'robotale report FILE.csv --out --json':52} {command:7.2f} s")


def measure_truth(missions: int, folder: Path, runs: int) -> None:
    """The truth check of generated missions, per mission, against the findings of their log."""
    # the oracle lives with the tests, apart from robotale, so that it cannot share its mistakes
    sys.path.insert(0, str(BENCHMARKS.parent / "tests" / "truth"))
    import compare  # here: the path above first, and only this measurement simulates
    import oracle

    from robotale.enhancement.findings import find
    from robotale.sim.batch import simulate_batch
    from robotale.sim.generate import DELAY_THRESHOLD, generate
    from robotale.sim.plans import plans
    from robotale.sim.worldspec import load_world

    checking, finding, disagreeing = [], [], 0
    for seed in range(1, missions + 1):
        mission = generate(seed, folder / f"mission_{seed}")
        batch = folder / f"mission_{seed}" / "runs"
        quietly(simulate_batch, plans(load_world(mission.world), "generated", runs=1, seed=seed),
                batch, workers=0)  # fmt: skip
        log = compare.prepared(batch)
        check, found = [], []
        for _ in range(runs):  # interleaved: check, findings, check, findings ...
            compare._TABLES.clear()  # the check analyses the log afresh each time
            check.append(timed(compare.disagreements, batch, log, DELAY_THRESHOLD))
            found.append(timed(find, log))
        sent = oracle.message_counts(oracle.load_batch(batch), DELAY_THRESHOLD)["sent"]
        said = len(compare._message_table(log, DELAY_THRESHOLD))
        if difference := messages_differ(seed, sent, said):
            raise SystemExit(difference)
        disagreeing += len(compare.disagreements(batch, log, DELAY_THRESHOLD))
        checking.append(min(check))
        finding.append(min(found))
    per_check, per_find = statistics.mean(checking), statistics.mean(finding)
    print(f"== truth check, {missions} generated missions (best of {runs}, messages checked equal)")
    print(f"  {'truth check per mission':52} {per_check:7.2f} s")
    print(f"  {'findings per mission (same log)':52} {per_find:7.2f} s")
    print(f"  {'truth check / findings':52} {per_check / per_find:7.2f} x")
    print(f"  {'disagreements found':52} {disagreeing:7d}")


def messages_differ(mission: int, sent: int, listed: int) -> str:
    """Empty when robotale lists as many messages as the simulation's truth sent in a
    mission (the truth check and the findings then judged the same messages); else why."""
    if sent == listed:
        return ""
    return f"mission {mission}: the truth sent {sent} messages, robotale lists {listed}"


def same_work(log) -> None:
    """pm4py's same work for the report: with the rework per activity."""
    pm4py_same_work(log, rework=True)


def measure_stored(size: int, name: str, folder: Path) -> None:
    from robotale.commands.report import report_command

    seconds = timed(quietly, report_command, log_name=name, json_out=folder / "stored.json")
    print(f"  {f'robotale report --log (stored, {size:,} events)':52} {seconds:7.2f} s")


def measure_pages(logs: dict[int, str], repeat: int) -> None:
    from playwright.sync_api import sync_playwright

    from robotale.webapp import create_app
    from robotale.webapp.serve import Dashboard

    sys.path.insert(0, str(BENCHMARKS.parent / "tests" / "webapp"))
    from browser import launch

    with tempfile.TemporaryDirectory(prefix="robotale-bench-web-") as scratch:
        folder = Path(scratch)
        app = create_app(upload_dir=folder / "uploads", model_dir=folder / "models")
        logging.getLogger("werkzeug").setLevel(logging.WARNING)
        with Dashboard(app, port=0) as dashboard, sync_playwright() as playwright:
            context = launch(playwright, folder / "profile")
            page = context.new_page()
            page.goto(f"{dashboard.url}/cypher")  # the browser's cache of the scripts
            for size, name in logs.items():
                target = PAGE_TARGETS.get(size)
                for cold in (True, False):
                    seconds = first_paint(page, dashboard, name, repeat, cold)
                    verdict = (
                        f"target < {target:.0f} s: {'met' if seconds < target else 'MISSED'}"
                        if target
                        else "no target"
                    )
                    print(f"{size:>9,} events: Findings page first paint {seconds:.2f} s "
                          f"({'cold' if cold else 'warm'}; {verdict})")  # fmt: skip
            context.close()


def forget_results(app, log: str) -> None:
    """Remove the results the dashboard keeps of ``log`` (its columnar copy stays, as after
    ``robotale ingest``)."""
    import shutil

    from robotale.ekg.columnar import log_build, results_folder
    from robotale.webapp.state import state

    shutil.rmtree(results_folder(log_build(state(app).neo4j.driver(), log)))


def first_paint(page, dashboard, log: str, repeat: int, cold: bool) -> float:
    """Median seconds from navigation start to the findings on screen; ``cold``: with the
    dashboard's caches of the log emptied first (a log stored by the command line), else as
    after the dashboard stored it (it prepares the findings while storing)."""
    from robotale.webapp.state import state

    timings = []
    for _ in range(repeat):
        current = state(dashboard.app)
        if cold:
            current.logs.forget(log)
            forget_results(dashboard.app, log)
        page.goto(f"{dashboard.url}/findings?log={log}")
        page.wait_for_function(SHOWN, timeout=600_000)
        timings.append(page.evaluate(MARK) / 1000)
    return statistics.median(timings)


if __name__ == "__main__":
    sys.exit(main())
