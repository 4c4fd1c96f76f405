"""The command a user runs, whole, against PromG's whole build of the same log.

    python benchmarks/ekg_build.py --whole-command [--sizes 100000 1000000] [--repeat 2]
        [--pages background|visit] [--promg-venv VENV] [--promg-server stock|robotale]

For each size, ``ekg_build.py``'s synthetic log is written once as a CSV (robotale's input)
and once as PromG's records (``peers.py``); then, interleaved (robotale, PromG, robotale,
PromG ...) on emptied databases of two private servers: one with APOC for PromG, and one
without plugins for robotale, as robotale sets a server up for a user (plugins cost a restart
the time to load their classes: about 27 s for APOC core and extended at 1M events and load
15, a cost robotale's user does not pay). PromG's server is, with ``--promg-server stock``
(the default), Neo4j as PromG's users run it: Neo4j's own launcher and stock ``neo4j.conf``
(``stock_neo4j.py``: G1 and the other stock JVM options; only the ports, data folder,
password and APOC changed, and the heap and page cache set as robotale's server's: the same
memory); with ``--promg-server robotale``, a server started by robotale's own launch code
(``peers.py``'s: robotale's JVM options, the parallel collector). The pairing is printed:

- robotale: the process ``python -m robotale ingest LOG.csv --entities robot,msg_id
  --aggregate activity --build BUILD`` from its start to its exit (reading the CSV, the build,
  the columnar copy), run as a user runs it against robotale's own local server (the private
  server is that server: its home is the ingest's robotale home, no ``NEO4J_URI``), so
  ``--build auto`` (the default) takes the bulk path (Neo4j's offline importer, the server
  stopped and started again) where the ingest would; the benchmark holds no connection to the
  server while an ingest runs (another client keeps the bulk path from being taken); the
  dashboard's pages are prepared afterwards by a process of their own, whose time
  until done is printed apart and awaited before the next build; with ``--pages visit`` none
  is started, which leaves the command's own work unchanged and keeps a large size's
  preparation from taking the machine between the timed runs);
- PromG: the process ``peers_promg.py`` (PromG's import, records, events, entities, CORR, DF,
  classes, DF_A) from its start to its exit.

Printed per size: each side's best wall time, its CPU time (the process with the importer it
waits for, and the Neo4j server, read from ``/proc``, every server process the run saw),
PromG's time over robotale's, the peak memory of robotale's process, the
load average, and the graphs' counts side by side, checked equal where both build the same
thing (events, entities, CORR, classes, OBSERVED).
"""

from __future__ import annotations

import json
import os
import re
import signal
import subprocess
import sys
import tempfile
import time
from contextlib import ExitStack
from dataclasses import dataclass, field
from pathlib import Path

import pandas as pd

from robotale.timings import process_seconds

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))

import importer_bound  # noqa: E402
import peers  # noqa: E402
from ekg_build import event_properties, synthetic_log  # noqa: E402
from peers import children_cpu, server_cpu  # noqa: E402
from stock_neo4j import describe_pairing, stock_neo4j  # noqa: E402

#: how PromG's server is started: as its users run it (the default), or by robotale's code
PROMG_SERVERS = ("stock", "robotale")

#: the rows both builders make the same of one log: (row, robotale's key, PromG's key)
SAME_ROWS = ("events", "entities", "CORR", "classes", "OBSERVED")
SAME = [row for row in peers.ROWS if row[0] in SAME_ROWS]


@dataclass
class Run:
    wall: float
    cpu: float
    server_cpu: float
    counts: dict[str, int] = field(default_factory=dict)
    peak_mb: float = 0.0
    pages: float | None = None
    bulk: bool = False  # the ingest took the bulk path


def main(
    sizes: list[int],
    repeat: int,
    heap: str,
    venv: Path | None = None,
    pages: str = "background",
    build: str = "auto",
    promg_server: str = "stock",
) -> int:
    # each line as it is printed: a run stopped from outside (a time limit, the kernel's
    # out-of-memory killer) leaves what was measured until then, not an empty output
    sys.stdout.reconfigure(line_buffering=True)  # type: ignore[union-attr]
    signal.signal(signal.SIGTERM, stopped)
    print(f"load average before: {os.getloadavg()[0]:.1f} on {os.cpu_count()} cores")
    pairing = describe_pairing(promg_server, heap)
    print(pairing)
    with tempfile.TemporaryDirectory(prefix="robotale-whole-") as folder:
        work = Path(folder)
        # the ingests' columnar copies and prepared pages in a home of the benchmark's own;
        # the download cache (the Neo4j jars) stays the user's
        from robotale.config import cache_dir

        os.environ["ROBOTALE_CACHE"] = str(cache_dir())
        (work / "robotale-home").mkdir()
        os.environ["ROBOTALE_HOME"] = str(work / "robotale-home")
        if venv == Path("none"):  # robotale's side only (e.g. the two build paths apart)
            python, why_not = None, "--promg-venv none"
        elif venv is not None:  # one that has PromG already
            python, why_not = venv / "bin" / "python", None
        else:
            python, why_not = peers.promg_environment(work / "venv")
        with peers.private_neo4j(work / "robotale", heap, apoc=False) as (shared, server):
            shared.close()  # a connection held open would keep the ingest from the bulk path
            ours = Reconnecting(server)
            with ExitStack() as stack:
                theirs = None
                if python is not None:
                    theirs = stack.enter_context(promg_neo4j(promg_server, work, heap))
                for size in sizes:
                    measure(
                        size, repeat, work, (ours, server), theirs, python, why_not, pages, build
                    )
                    print(f"  ({pairing})")
            ours.release()
    print(f"load average after: {os.getloadavg()[0]:.1f}")
    return 0


def promg_neo4j(kind: str, work: Path, heap: str):
    """PromG's private server (``with``: its driver and server) of the pairing ``kind``."""
    if kind == "stock":
        return stock_neo4j(work / "promg-server", heap)
    if kind == "robotale":
        return peers.private_neo4j(work, heap)
    raise ValueError(f"--promg-server {kind!r}: give one of {', '.join(PROMG_SERVERS)}")


class Reconnecting:
    """A driver to the private server opened when first used and closed by :meth:`release`:
    between an ingest's runs the benchmark holds no connection, and after an ingest that
    replaced the database no bookmark of the old one."""

    def __init__(self, server) -> None:
        self.server, self.driver = server, None

    def __getattr__(self, name: str):
        if self.driver is None:
            from robotale.ekg.connection import Settings, connect

            running = self.server.running()
            where = Settings(running.bolt_uri, "neo4j", self.server.password() or "", True)
            self.driver = connect(where)
        return getattr(self.driver, name)

    def release(self) -> None:
        if self.driver is not None:
            self.driver.close()
            self.driver = None


def measure(
    size: int,
    repeat: int,
    work: Path,
    ours,
    theirs,
    python,
    why_not,
    pages: str,
    build: str = "auto",
) -> None:
    """``ours`` and ``theirs``: (driver, server) of robotale's and PromG's servers."""
    print(f"{size:,} events: load average {os.getloadavg()[0]:.1f} at the start", flush=True)
    log = synthetic_log(size)
    csv = work / f"log{size}.csv"
    canonical_csv(log).to_csv(csv, index=False)
    robotale_runs: list[Run] = []
    promg_runs: list[Run] = []
    for turn in range(1, repeat + 1):
        mine = robotale_ingest(csv, *ours, pages, build)
        robotale_runs.append(mine)
        print(f"  turn {turn}: {said(mine, 'robotale')}")
        if python is not None and theirs is not None:
            print(f"  turn {turn}: PromG started (load average {os.getloadavg()[0]:.1f})")
            run, why_not = promg_whole(python, *theirs, log, work)
            if run is not None:
                promg_runs.append(run)
                print(f"  turn {turn}: {said(run, 'PromG')}")
            else:
                print(f"  turn {turn}: PromG did not finish: {why_not}")
    report(size, robotale_runs, promg_runs, why_not, event_properties(log), pages, build)


def said(run: Run, who: str) -> str:
    """One run's figures on one line, printed as it ends."""
    return (
        f"{who} {run.wall:.1f} s wall, {run.cpu:.1f} s CPU (+ Neo4j {run.server_cpu:.1f} s); "
        f"load average {os.getloadavg()[0]:.1f}"
    )


def canonical_csv(log: pd.DataFrame) -> pd.DataFrame:
    """The log as robotale's CSV names it (``time``, ``activity``, ``robot`` ...)."""
    from robotale.eventlog import schema

    return schema.to_csv_names(log)


class ServerCpu:
    """The CPU seconds the server's processes spend from now on: the last reading of each
    process seen (one that ended keeps its last reading)."""

    def __init__(self, server) -> None:
        self.server = server
        running = server.running()
        self.start = {running.pid: process_cpu(running.pid)} if running else {}
        self.last = dict(self.start)

    def sample(self) -> None:
        running = self.server.running()
        if running is not None:
            self.last[running.pid] = process_cpu(running.pid) or self.last.get(running.pid, 0.0)

    def spent(self) -> float:
        return sum(cpu - self.start.get(pid, 0.0) for pid, cpu in self.last.items())


def process_cpu(pid: int) -> float:
    """CPU seconds the process ``pid`` has used so far (0 when it is gone)."""
    return process_seconds(pid) or 0.0


def timed_process(command: list[str], server, **options) -> tuple[Run, int, str, str]:
    """Run ``command`` to its end: its wall and CPU time, the server's CPU time meanwhile (of
    every server process seen: a bulk ingest stops the server and starts a new one) and the
    process's peak resident memory (its high-water mark, read while it runs); its exit
    status, stdout and stderr (in files: a full pipe would stop it)."""
    with tempfile.TemporaryFile("w+") as out, tempfile.TemporaryFile("w+") as err:
        cpu = children_cpu()
        servers = ServerCpu(server)
        started = time.perf_counter()
        process = subprocess.Popen(command, stdout=out, stderr=err, text=True, **options)
        peak = 0.0
        while process.poll() is None:
            peak = max(peak, high_water_mb(process.pid))
            servers.sample()
            time.sleep(0.05)
        wall = time.perf_counter() - started
        servers.sample()
        run = Run(wall, children_cpu() - cpu, servers.spent(), peak_mb=peak)
        out.seek(0)
        err.seek(0)
        return run, process.returncode, out.read(), err.read()


def high_water_mb(pid: int) -> float:
    """The peak resident memory of the process ``pid`` so far (0 when it is gone)."""
    try:
        status = Path(f"/proc/{pid}/status").read_text()
    except OSError:
        return 0.0
    found = re.search(r"VmHWM:\s+(\d+) kB", status)
    return int(found.group(1)) / 1024 if found else 0.0


def with_bytecode(environment: dict[str, str], folder: Path) -> dict[str, str]:
    """``environment`` with robotale's bytecode kept in ``folder`` between runs, compiled
    once before the first (untimed), as an installed package runs: a shell that sets
    ``PYTHONDONTWRITEBYTECODE`` would have the command compile its some 500 modules on every
    run (about 0.2 s of CPU), while PromG's package has the bytecode pip wrote."""
    kept = {k: v for k, v in environment.items() if k != "PYTHONDONTWRITEBYTECODE"}
    kept["PYTHONPYCACHEPREFIX"] = str(folder)
    if not folder.exists():
        warm = [sys.executable, "-c", "import robotale.cli, robotale.commands.ingest"]
        subprocess.run(warm, env=kept, check=True)
    return kept


def robotale_ingest(
    csv: Path, driver, server, pages: str = "background", build: str = "auto"
) -> Run:
    from robotale.results.background import done_file

    peers.clear(driver)
    driver.release()
    # the private server as robotale's own local server: its home is the ingest's
    environment = {k: v for k, v in os.environ.items() if not k.startswith("NEO4J_")}
    environment |= {"ROBOTALE_HOME": str(server.root), "ROBOTALE_PAGES": pages}
    environment = with_bytecode(environment, server.root / "bytecode")
    command = [sys.executable, "-m", "robotale", "ingest", str(csv), "--log", "whole"]
    command += ["--entities", "robot,msg_id", "--aggregate", "activity", "--replace"]
    command += ["--build", build]
    run, status, stdout, stderr = timed_process(command, server, env=environment)
    if status != 0:
        raise SystemExit(failure("robotale ingest", status, stderr, run, server))
    run.bulk = "neo4j-admin" in stdout
    # the graph the command built, counted before the pages' preparation adds the class
    # graph the Perspectives page shows (by activity and robot)
    run.counts = peers.counts(driver)
    # the pages are prepared after the command: awaited, so they slow neither side's next run
    preparing = re.search(r"in the background \(process (\d+)\)", stdout)
    done = done_file(driver, "whole")
    while preparing and not done.exists() and alive(int(preparing.group(1))):
        time.sleep(0.2)
    run.pages = json.loads(done.read_text())["seconds"] if done.exists() else None
    return run


def failure(who: str, status: int, stderr: str, run: Run, server) -> str:
    """Why a timed process failed, in one sentence: its exit status or the signal that ended
    it (SIGKILL with a high peak memory: the kernel's out-of-memory killer, as its log says),
    its last line on stderr, and whether the server it used still runs."""
    if status < 0:
        how = f"was ended by {signal.Signals(-status).name}"
        if -status == signal.SIGKILL:
            how += " (the kernel's out-of-memory killer sends it: see `dmesg`)"
    else:
        how = f"exited with status {status}"
    lines = [line for line in stderr.strip().splitlines() if line.strip()]
    said = f", saying: {lines[-1].strip()}" if lines else ", saying nothing on stderr"
    up = "still runs" if server.running() is not None else "no longer runs"
    return (
        f"{who} {how} after {run.wall:.1f} s (peak memory {run.peak_mb:,.0f} MB){said}; "
        f"its Neo4j server {up}; load average {os.getloadavg()[0]:.1f}"
    )


def stopped(number: int, frame) -> None:
    """A SIGTERM (a time limit, ``kill``) ends the benchmark as an error that says so: the
    servers are stopped and what was printed stays."""
    raise SystemExit(
        f"the benchmark was stopped by {signal.Signals(number).name} (load average "
        f"{os.getloadavg()[0]:.1f})"
    )


def alive(pid: int) -> bool:
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    return True


def promg_whole(python: Path, driver, server, log: pd.DataFrame, work: Path):
    """PromG's whole build as a process; None and why when it failed."""
    cpu, neo4j = children_cpu(), server_cpu(server)
    build, why_not = peers.promg_build(python, driver, server, log, work, PromgOptions())
    if build is None:
        return None, why_not
    spent, served = children_cpu() - cpu, server_cpu(server) - neo4j
    return Run(build.process_seconds, spent, served, counts=build.counts), None


@dataclass(frozen=True)
class PromgOptions:
    batch_size: int = 10_000


def best(runs: list[Run]) -> Run:
    return min(runs, key=lambda run: run.wall)


def same_counts(ours: dict[str, int], theirs: dict[str, int]) -> list[str]:
    """The rows both builders make the same of a log whose counts differ (empty: none)."""
    return [
        f"{row}: robotale {peers._count(ours, mine):,}, PromG {peers._count(theirs, other):,}"
        for row, mine, other in SAME
        if peers._count(ours, mine) != peers._count(theirs, other)
    ]


def report(
    size: int,
    ours: list[Run],
    theirs: list[Run],
    why_not: str | None,
    properties: int,
    when: str = "background",
    build: str = "auto",
) -> None:
    mine = best(ours)
    path = "bulk path (neo4j-admin import)" if mine.bulk else "online path (Cypher batches)"
    if when == "visit":
        pages = "on first visit (--pages visit)"
    elif mine.pages is not None:
        pages = f"{mine.pages:.1f} s after it, in the background"
    else:
        pages = "NOT: the background preparation ended without finishing"
    print(
        f"  walls: robotale {[round(r.wall, 1) for r in ours]}, PromG "
        f"{[round(r.wall, 1) for r in theirs]} (in turns)"
    )
    print(
        f"\n{size:,} events, whole `robotale ingest --build {build}` (CSV read to exit; took "
        f"the {path}): {mine.wall:.1f} s wall, "
        f"{mine.cpu:.1f} s CPU (+ Neo4j {mine.server_cpu:.1f} s), peak memory "
        f"{mine.peak_mb:,.0f} MB; pages prepared {pages} (best of {len(ours)}; load "
        f"average {os.getloadavg()[0]:.1f})"
    )
    nodes, edges = importer_bound.shape(mine.counts)
    importer_bound.print_bound(nodes, properties, edges, mine.wall)
    if not theirs:
        print(f"  PromG: not run. {why_not}")
        return
    other = best(theirs)
    differences = same_counts(mine.counts, other.counts)
    print(
        f"  PromG's whole build (process start to exit): {other.wall:.1f} s wall, "
        f"{other.cpu:.1f} s CPU (+ Neo4j {other.server_cpu:.1f} s): ratio "
        f"{other.wall / mine.wall:.2f} wall, "
        f"{(other.cpu + other.server_cpu) / (mine.cpu + mine.server_cpu):.2f} CPU "
        f"(PromG's / robotale's; target >= 2.5); interleaved, best of {len(theirs)}"
    )
    print(
        "  same events, entities, CORR, classes, OBSERVED: "
        + ("yes" if not differences else f"NO: {'; '.join(differences)}")
    )
    peers._table(peers.Build(mine.wall, mine.counts), peers.Build(other.wall, other.counts, ""))
