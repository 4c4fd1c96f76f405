"""How fast robotale runs an aggregation specification, against the same steps as plain Cypher.

    python benchmarks/aggregate.py [--sizes 35000 1000000 5000000] [--repeat 3]
        [--heap 3g] [--pagecache 2g] [--timeout 3600] [--min-available 4] [--no-floor]

For each size it starts a private Neo4j (a temporary robotale home on free ports, with the
heap and page cache given, printed; the jars come from the usual cache), writes a logistics
log shaped like OCEAN's published one (containers, customer orders, forklifts, trucks,
vehicles; ``tests/ekg/ocean_shaped.py``) to a CSV a slice at a time, with one attribute table
per object type, and ingests it as a user would: ``robotale ingest EVENTS.csv --entities
<the object types>`` (``--build auto``: Neo4j's offline importer from 300,000 events; an
``--objects`` folder would make the build online, so the objects' attributes are then set by
a batched ``UNWIND ... SET`` read from the tables a slice at a time). Then it runs OCEAN's
logistics specification of five steps (two entity steps splitting the orders by a where, an
event step grouped by activity and the orders' aggregates, a time-split event step;
attributes with MULTISET, AVG, MINMAX, SUM, MIN, MAX):

- robotale: ``robotale.ekg.steps.run_spec`` (nodes read and grouped in pandas, aggregates
  and memberships written in batches, the log's edges read once and lifted in memory, the
  lifted edges written in batches);
- plain: the same steps as the field writes them, one ``MATCH ... CREATE`` per step, then
  (as OCEAN relates its classes once, after its steps) one query per step and kind of
  lifted edge, the edges created in batches (``CALL ... IN TRANSACTIONS``) so a million
  events fit the server's limit on a transaction's memory
  (``benchmarks/aggregate_plain.cypher``).

Both write the lifted edges of the level the five steps end at, one per pair of ends, kind
(and entity type, for DF) with its count, each owned by the later step of its two ends.

Each run is a process of its own, stopped after ``--timeout`` seconds (its server-side
queries terminated, its writes removed): every run ends with a line for each side, its time
or "did not finish in N s". Its peak memory and the machine's available memory are watched
(printed each minute); a run is stopped when the available memory falls under
``--min-available`` GiB. Interleaved (robotale, plain, robotale, plain ...), the best of
``--repeat`` each (wall time, and CPU time of the run's process and Neo4j's, which a busy
shared machine does not inflate), the outputs checked equal (the aggregates with all their
properties; the lifted edges, read one aggregate at a time, counted and hashed with their
counts), the graph restored between runs. After each robotale run it prints robotale's parts
(wall and CPU time of each, timed by wrapping robotale's own functions, and the process's
peak memory when each ended) and, unless ``--no-floor``, the floor of its largest part: as
many relationships between the same ends, with a lifted edge's properties, written by a
trivial ``UNWIND ... CREATE`` (``cypher/aggr_bound_edges.cypher``) in robotale's batches.
Printed beside: OCEAN's published figures (its logistics log of 35k events in 1.9 s; BPIC17,
1.2M events and 224k entities, in 28.6 s).
Targets: robotale at least 3x the plain queries; a 1.2M-event specification of five steps
under 15 s.
"""

from __future__ import annotations

import argparse
import hashlib
import multiprocessing
import os
import re
import subprocess
import sys
import tempfile
import time
from dataclasses import dataclass, field
from pathlib import Path

import pandas as pd

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))
sys.path.insert(0, str(HERE.parent / "tests" / "ekg"))
from ocean_shaped import LOGISTICS_SPEC, write_logistics  # noqa: E402
from peers import children_cpu  # noqa: E402
from whole_ingest import high_water_mb, process_cpu  # noqa: E402

from robotale.ekg import lift, steps, writelock  # noqa: E402
from robotale.ekg.connection import Settings, connect, database  # noqa: E402
from robotale.ekg.load import Loader  # noqa: E402
from robotale.ekg.spec import parse_spec  # noqa: E402
from robotale.ekg.steps import run_spec, undo  # noqa: E402
from robotale.queries import split_statements, statements  # noqa: E402

OCEAN = {35_413: 1.9, 1_200_000: 28.6}  # events -> seconds, OCEAN's paper
CUTOFF = pd.Timestamp("2024-03-01T00:00:00Z").to_pydatetime()
PLAIN = split_statements((HERE / "aggregate_plain.cypher").read_text(), comments=True)
SIDES = ("robotale", "plain")
GIB = 1024**3


def plain(name: str) -> list[str]:
    """The statements of aggregate_plain.cypher with a comment line starting with ``name``."""
    return [s for s in PLAIN if re.search(rf"^// {re.escape(name)}", s, re.MULTILINE)]


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--sizes", type=int, nargs="+", default=[35_000])
    parser.add_argument("--repeat", type=int, default=3, help="runs of each, the best counts")
    parser.add_argument("--heap", default="3g", help="heap of the private Neo4j (3g)")
    parser.add_argument("--pagecache", default="2g", help="its page cache (2g)")
    parser.add_argument(
        "--timeout", type=float, default=3600, help="seconds a side's run may take (3600)"
    )
    parser.add_argument(
        "--min-available",
        type=float,
        default=4,
        help="GiB of available memory under which a run is stopped (4)",
    )
    parser.add_argument(
        "--no-floor", dest="floor", action="store_false", help="skip the edge-writing floor"
    )
    args = parser.parse_args()
    sys.stdout.reconfigure(line_buffering=True)  # type: ignore[union-attr]
    print(f"load average before: {os.getloadavg()[0]:.1f} on {os.cpu_count()} cores")
    print(
        f"private Neo4j: heap {args.heap}, page cache {args.pagecache}; a side's run stopped "
        f"after {args.timeout:.0f} s or under {args.min_available:g} GiB of available memory"
    )
    limits = Limits(args.timeout, args.min_available * GIB)
    for size in args.sizes:
        with private_server(args.heap, args.pagecache) as server:
            measure(server, size, args.repeat, limits, args.floor)
    print(f"load average after: {os.getloadavg()[0]:.1f}")
    return 0


@dataclass(frozen=True)
class Limits:
    seconds: float  # a side's run
    available: float  # bytes of available memory below which a run is stopped


class private_server:
    """A Neo4j for one size only, robotale's local server of a temporary robotale home (so
    ``robotale ingest`` may take its bulk path), stopped and removed at the end."""

    def __init__(self, heap: str, pagecache: str) -> None:
        self.heap, self.pagecache = heap, pagecache

    def __enter__(self) -> private_server:
        from robotale.config import cache_dir
        from robotale.neo4j_server.server import LocalServer, ServerOptions, free_port

        os.environ["ROBOTALE_CACHE"] = str(cache_dir())  # the jars stay the user's
        self.folder = tempfile.TemporaryDirectory(prefix="robotale-aggregate-")
        self.work = Path(self.folder.name)
        root = self.work / "home"
        root.mkdir()
        # this process and the runs' read the log's columnar copy from this home
        os.environ["ROBOTALE_HOME"] = str(root)
        for key in [k for k in os.environ if k.startswith("NEO4J_")]:
            del os.environ[key]
        self.server = LocalServer(root)
        options = ServerOptions(free_port(), free_port(), heap=self.heap, pagecache=self.pagecache)
        self.server.start(options)
        return self

    def settings(self) -> Settings:
        running = self.server.running()
        assert running is not None, "the private Neo4j stopped"
        return Settings(running.bolt_uri, "neo4j", self.server.password() or "", True)

    def pid(self) -> int:
        running = self.server.running()
        return running.pid if running is not None else 0

    def __exit__(self, *exc: object) -> None:
        self.server.stop()
        self.folder.cleanup()


def measure(server: private_server, size: int, repeat: int, limits: Limits, floor: bool) -> None:
    name = f"logistics_{size}"
    types = generate(server.work, size)
    if not ingest(server, size, name, types, limits):
        return
    pid = server.pid()
    driver = connect(server.settings())
    try:
        compare(driver, server, name, size, repeat, limits, floor, pid)
    finally:
        driver.close()


def generate(work: Path, size: int) -> list[str]:
    began, cpu = time.perf_counter(), os.times()
    types = write_logistics(size, work)
    spent = sum(os.times()[:2]) - sum(cpu[:2])
    megabytes = (work / "events.csv").stat().st_size / 1024**2
    print(
        f"\n{size:,} events: the log written in {time.perf_counter() - began:.0f} s (CPU "
        f"{spent:.0f} s), {megabytes:,.0f} MB; this process's peak memory so far "
        f"{high_water_mb(os.getpid()):,.0f} MiB"
    )
    return types


def ingest(server: private_server, size: int, name: str, types: list[str], limits: Limits) -> bool:
    """``robotale ingest`` of the written log, then the objects' attributes; False when it was
    stopped (memory) or failed."""
    command = [sys.executable, "-m", "robotale", "ingest", str(server.work / "events.csv")]
    command += ["--log", name, "--entities", ",".join(types), "--pages", "visit"]
    began, cpu, spent = time.perf_counter(), children_cpu(), process_cpu(server.pid())
    with open(server.work / "ingest.out", "w+") as out:
        process = subprocess.Popen(command, stdout=out, stderr=subprocess.STDOUT, text=True)
        watch = Watch(process.pid, server, limits.available, f"ingest of {size:,}")
        stopped = watch.until(lambda: process.poll() is not None, None)
        if stopped:
            process.kill()
        process.wait()
        out.seek(0)
        said = out.read()
    wall = time.perf_counter() - began
    if stopped or process.returncode != 0:
        print(f"  robotale ingest {stopped or 'failed'}; its output ends:\n{said[-2000:]}")
        return False
    how = "bulk (neo4j-admin import)" if "neo4j-admin" in said else "online"
    print(
        f"  robotale ingest ({how}): {wall:.0f} s, CPU {children_cpu() - cpu:.0f} s (Neo4j "
        f"{watch.server_cpu - spent:.0f} s, restarted: counted from its last start), peak memory "
        f"{watch.peak:,.0f} MiB; Neo4j's peak resident memory {watch.server_peak:,.0f} MiB; "
        f"available memory at least {watch.least / GIB:.1f} GiB"
    )
    began = time.perf_counter()
    driver = connect(server.settings())
    try:
        set_attributes(driver, server.work / "objects", name, types)
    finally:
        driver.close()
    print(f"  the objects' attributes set in {time.perf_counter() - began:.0f} s")
    return True


def set_attributes(driver, folder: Path, name: str, types: list[str]) -> None:
    """The object tables' attributes on the entities, 10,000 rows a transaction, read from
    the tables a slice at a time."""
    [query] = plain("attributes")
    for kind in types:
        for table in pd.read_csv(folder / f"{kind}.csv", dtype={"id": str}, chunksize=10_000):
            driver.execute_query(
                query, rows=table.to_dict("records"), log=name, type=kind, database_=database()
            )


@dataclass
class Run:
    """One side's run: its times, or why it ended without a result."""

    wall: float = 0.0
    cpu: float = 0.0  # the run's process and Neo4j
    own: float = 0.0  # the run's process alone
    peak: float = 0.0  # MiB, the run's process
    parts: dict[str, list[float]] = field(default_factory=dict)
    failed: str = ""


def compare(driver, server, name, size, repeat, limits, floor, pid) -> None:
    runs: dict[str, list[Run]] = {kind: [] for kind in SIDES}
    outputs: dict[str, object] = {}
    for turn in range(repeat):
        for kind in SIDES:  # interleaved: robotale, plain, robotale, plain ...
            # the size's server is removed after its last run: nothing to restore (at 5M
            # events removing the aggregates' memberships takes minutes)
            last = turn == repeat - 1 and kind == SIDES[-1]
            run = run_side(kind, server.settings(), name, pid, limits, server)
            runs[kind].append(run)
            print(f"  load {os.getloadavg()[0]:.1f}: {said(kind, run, limits)}")
            if run.failed:
                if not last:
                    restore(driver, name, kind)
                continue
            if kind == "robotale":
                print(f"  robotale's parts, wall/CPU s (peak MiB at its end): {parts_line(run)}")
                if floor:
                    print_bound(driver, name, pid, run.parts["creating the lifted edges"])
            found = output(driver, name)
            print(f"  {kind}'s output: {len(found[0]):,} aggregates, {found[1]:,} lifted edges")
            if outputs.setdefault(kind, found) != found:
                raise SystemExit(f"{kind} wrote something else on a second run")
            if not last:
                restore(driver, name, kind)
    done = {k: [r for r in v if not r.failed] for k, v in runs.items()}
    for kind in SIDES:
        if not done[kind]:
            print(f"  {kind}: no run finished ({said(kind, runs[kind][0], limits)})")
    if "robotale" in outputs and "plain" in outputs:
        if outputs["robotale"] != outputs["plain"]:
            raise SystemExit("robotale and the plain queries wrote different aggregates or edges")
        aggregates, edges, _ = outputs["robotale"]  # type: ignore[misc]
        print(f"  outputs equal: {len(aggregates):,} aggregates, {edges:,} lifted edges")
    else:
        print("  outputs not compared: a side did not finish")
    best = {k: min(r.wall for r in v) for k, v in done.items() if v}
    least = {k: min(r.cpu for r in v) for k, v in done.items() if v}
    if len(best) == 2:
        print(
            f"  best of {repeat}: robotale {best['robotale']:.2f} s, plain Cypher "
            f"{best['plain']:.2f} s: {best['plain'] / best['robotale']:.1f}x (target 3x)"
        )
        print(
            f"  least CPU (the run's process and Neo4j) of {repeat}: robotale "
            f"{least['robotale']:.2f} s, plain Cypher {least['plain']:.2f} s: "
            f"{least['plain'] / least['robotale']:.1f}x"
        )
    if size >= 1_000_000 and "robotale" in best:
        scaled = best["robotale"] * 1_200_000 / size
        print(
            f"  robotale scaled to 1.2M events: {scaled:.1f} s (target < 15 s), CPU "
            f"{least['robotale'] * 1_200_000 / size:.1f} s"
        )
    for events, seconds in OCEAN.items():
        print(f"  OCEAN's published figure: {events:,} events in {seconds} s (its machine)")


def said(kind: str, run: Run, limits: Limits) -> str:
    if run.failed:
        return f"{kind} {run.failed}"
    return (
        f"{kind} {run.wall:.2f} s (CPU {run.cpu:.2f} s, of which its process {run.own:.2f} s; "
        f"its peak memory {run.peak:,.0f} MiB)"
    )


def parts_line(run: Run) -> str:
    return "; ".join(f"{k} {w:.1f}/{c:.1f} ({m:,.0f})" for k, (w, c, m) in run.parts.items())


def run_side(kind: str, where: Settings, name: str, pid: int, limits: Limits, server) -> Run:
    """One run of ``kind`` in a process of its own, stopped after ``limits.seconds`` or when
    the available memory falls under ``limits.available``."""
    context = multiprocessing.get_context("spawn")
    receiving, sending = context.Pipe(duplex=False)
    process = context.Process(target=side, args=(kind, where, name, pid, sending))
    process.start()
    sending.close()
    watch = Watch(process.pid, server, limits.available, kind)
    deadline = time.perf_counter() + limits.seconds
    stopped = watch.until(lambda: receiving.poll() or not process.is_alive(), deadline)
    run = Run()
    if stopped:
        process.kill()
        run.failed = stopped
    elif receiving.poll():
        run = receiving.recv()
    else:
        run.failed = f"ended with exit status {process.exitcode}"
    process.join()
    if stopped:
        terminate(where)
        print(f"  {kind}: stopped; its server-side transactions ended")
    return run


def side(kind: str, where: Settings, name: str, server: int, sending) -> None:
    """The process of one run: runs ``kind`` and sends back its :class:`Run`."""
    driver = connect(where)
    run = Run()
    try:
        with timed_parts(server) as parts:
            began, spent, own = time.perf_counter(), cpu_seconds(server), sum(os.times()[:2])
            if kind == "robotale":
                run_spec(driver, name, parse_spec(LOGISTICS_SPEC))
            else:
                run_plain(driver, name)
            run.wall = time.perf_counter() - began
            run.cpu, run.own = cpu_seconds(server) - spent, sum(os.times()[:2]) - own
        run.parts = parts.spent
        run.peak = high_water_mb(os.getpid())
    except Exception as error:  # the parent prints it and goes on to the other side
        run.failed = f"failed: {type(error).__name__}: {str(error)[:500]}"
    finally:
        driver.close()
    sending.send(run)


class Watch:
    """Waits for a process, reading its peak memory, Neo4j's, and the machine's available
    memory twice a second (a line each minute)."""

    def __init__(self, pid: int, server, available: float, label: str) -> None:
        self.pid, self.server, self.available, self.label = pid, server, available, label
        self.peak = self.server_peak = self.server_cpu = 0.0
        self.least = float("inf")

    def until(self, done, deadline: float | None) -> str:
        """Waits until ``done()``; the reason it stopped waiting first, else ''."""
        began = time.perf_counter()
        said = began
        while not done():
            now = time.perf_counter()
            if deadline is not None and now > deadline:
                return f"did not finish in {now - began:.0f} s"
            self.sample()
            if self.least < self.available:
                left = self.least / GIB
                return f"stopped after {now - began:.0f} s: available memory {left:.1f} GiB"
            if now - said >= 60:
                said = now
                print(
                    f"    {self.label}: {now - began:.0f} s, peak memory {self.peak:,.0f} MiB, "
                    f"Neo4j {self.server_peak:,.0f} MiB, available {self.least / GIB:.1f} GiB, "
                    f"load {os.getloadavg()[0]:.1f}"
                )
            time.sleep(0.5)
        return ""

    def sample(self) -> None:
        self.peak = max(self.peak, high_water_mb(self.pid))
        pid = self.server.pid()
        if pid:
            self.server_peak = max(self.server_peak, high_water_mb(pid))
            self.server_cpu = process_cpu(pid) or self.server_cpu
        self.least = min(self.least, available_bytes())


def available_bytes() -> float:
    """The kernel's estimate of the memory available without swapping (MemAvailable)."""
    found = re.search(r"MemAvailable:\s+(\d+) kB", Path("/proc/meminfo").read_text())
    return int(found.group(1)) * 1024 if found else float("inf")


def terminate(where: Settings) -> None:
    """End the server's transactions of a stopped run (Neo4j goes on with a query whose client
    went away until it writes a result) and wait for them to end."""
    [running] = plain("running:")
    [ending] = plain("terminate:")
    driver = connect(where)
    try:
        for _ in range(120):
            records, _, _ = driver.execute_query(running, database_=database())
            ids = [r["transactionId"] for r in records]
            if not ids:
                return
            driver.execute_query(ending, ids=ids, database_=database())
            time.sleep(1)
    finally:
        driver.close()


def restore(driver, name: str, kind: str) -> None:
    """The graph as before a run: robotale's undo after a robotale run that finished, else the
    plain queries' removal (which also removes a stopped run's aggregates)."""
    if kind == "robotale":
        try:
            undo(driver, name, 1)
            return
        except Exception as error:  # a stopped run left no step records to undo
            print(f"  robotale's undo: {type(error).__name__}: {str(error)[:200]}; cleared")
    clear(driver, name)


#: robotale's parts timed in each of its runs: (label, owner, attribute)
PARTS = [
    ("reading the copy and deriving its edges", lift.LogEdges, "of_log"),
    # the lock's transaction: the run's checks, its Log node's build, the entities' keys
    ("the lock and the run's reads", writelock, "_take"),
    ("reading entities", steps, "_read_nodes"),
    ("events and their where", steps, "_event_nodes"),
    ("grouping", steps, "aggregate_table"),
    ("member lists", steps, "_write_members"),
    ("lifting in memory", lift.LogEdges, "lift_level"),
    ("creating the lifted edges", steps, "_write_lifted"),
    # a part of the one above: the one read of the element ids of the edges' free ends
    ("(of which the ends' element ids)", lift.LogEdges, "_read_stored"),
]


class timed_parts:
    """Wraps robotale's functions named in :data:`PARTS` with timers (wall, and CPU of this
    process and Neo4j) while a run lasts."""

    def __init__(self, server: int) -> None:
        self.server = server
        #: label -> wall, CPU, this process's peak memory (MiB) when it last ended
        self.spent: dict[str, list[float]] = {label: [0.0, 0.0, 0.0] for label, _, _ in PARTS}

    def __enter__(self) -> timed_parts:
        self.saved = [(owner, name, getattr(owner, name)) for _, owner, name in PARTS]
        for (label, owner, name), (_, _, function) in zip(PARTS, self.saved, strict=True):
            setattr(owner, name, self._timer(label, function))
        return self

    def __exit__(self, *exc: object) -> None:
        for owner, name, function in self.saved:
            setattr(owner, name, function)

    def _timer(self, label: str, function):
        """A plain function in ``function``'s place: on a class it is bound as the instance
        method was, and a classmethod taken from the class is already bound."""
        spent, server = self.spent[label], self.server

        def timed(*args, **kwargs):
            began, cpu = time.perf_counter(), cpu_seconds(server)
            try:
                return function(*args, **kwargs)
            finally:
                spent[0] += time.perf_counter() - began
                spent[1] += cpu_seconds(server) - cpu
                spent[2] = high_water_mb(os.getpid())

        return timed


def cpu_seconds(server: int) -> float:
    """CPU seconds this process and the Neo4j process ``server`` have used so far: on a
    shared machine wall time also counts the others' work."""
    own = os.times()
    return own.user + own.system + process_cpu(server)


def run_plain(driver, name: str) -> None:
    """The five steps, then their lifted edges (auto-commit: the edges go in batches)."""
    with driver.session(database=database()) as session:
        for step in range(1, 6):
            for statement in plain(f"step {step}:"):
                session.run(statement, log=name, cutoff=CUTOFF).consume()
        for step in range(1, 6):
            for statement in plain("lift:"):
                session.run(statement, log=name, step=step).consume()


def output(driver, name: str) -> tuple[list, int, str]:
    """Every aggregate (all properties, times as Unix nanoseconds, floats to 9 digits),
    sorted; the number of lifted edges and a hash of them all (ends, kind, entity type,
    count, step), read one aggregate at a time, each aggregate's sorted, in the order of the
    aggregates' ids: at 5M events the edges themselves would not be held."""
    [nodes] = plain("output: every aggregate")
    out, into = plain("output: every lifted edge")
    records, _, _ = driver.execute_query(nodes, log=name, database_=database())
    aggregates = sorted(tuple(sorted((k, comparable(v)) for k, v in r["a"].items()))
                        for r in records)  # fmt: skip
    edges, digest = 0, hashlib.sha256()
    with driver.session(database=database()) as session:
        for record in sorted(records, key=lambda r: r["a"]["id"]):
            lifted = []
            for query in (out, into):
                for r in session.run(query, log=name, aggregate=record["element"]):
                    lifted.append(tuple((k, "" if v is None else v) for k, v in r.items()))
            edges += len(lifted)
            digest.update(repr(sorted(lifted)).encode())
    return aggregates, edges, digest.hexdigest()


def print_bound(driver, name: str, server: int, writing: list[float]) -> None:
    """Neo4j's own rate for the lifted edges just written: as many relationships between the
    same ends, with a lifted edge's properties, written by a trivial ``UNWIND ... CREATE``
    (``cypher/aggr_bound_edges.cypher``) in robotale's batches; robotale's undo removes them."""
    [nodes] = plain("output: every aggregate")
    [ends] = plain("ends:")
    records, _, _ = driver.execute_query(nodes, log=name, database_=database())
    sources: list[str] = []
    targets: list[str] = []
    with driver.session(database=database()) as session:
        for aggregate in [r["element"] for r in records]:
            for r in session.run(ends, log=name, aggregate=aggregate):
                sources.append(r["source"])
                targets.append(r["target"])
    loader = Loader(driver, name, workers=steps.LIFT_WORKERS)
    began, spent = time.perf_counter(), cpu_seconds(server)
    loader.run("aggr_bound_edges", {"sources": sources, "targets": targets,
                                    "counts": [1] * len(sources)}, step=0)  # fmt: skip
    wall, cpu = time.perf_counter() - began, cpu_seconds(server) - spent
    print(
        f"  floor, load {os.getloadavg()[0]:.1f}: {len(sources):,} relationships between the "
        f"same ends by trivial UNWIND CREATE in {wall:.1f} s (CPU {cpu:.1f} s); robotale "
        f"created its lifted edges in {writing[0]:.1f} s (CPU {writing[1]:.1f} s): "
        f"{writing[0] / wall:.2f}x the floor's wall, {writing[1] / cpu:.2f}x its CPU"
    )


def comparable(value: object) -> object:
    if hasattr(value, "to_native") and hasattr(value, "nanosecond"):
        return pd.Timestamp(value.iso_format()).value  # a time: the same instant in any zone
    if isinstance(value, float):
        return float(f"{value:.9g}")
    if isinstance(value, list):
        return tuple(value)
    return value


def clear(driver, name: str) -> None:
    """Remove the plain queries' aggregates as robotale's undo does (batched: auto-commit)."""
    with driver.session(database=database()) as session:
        for statement in statements("aggr_undo"):
            session.run(statement, log=name, step=1).consume()


if __name__ == "__main__":
    sys.exit(main())
