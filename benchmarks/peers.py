"""PromG beside robotale: the same event log made into an event knowledge graph by both.

    python benchmarks/peers.py [--log CSV] [--synthetic 100000] [--heap 2g]

Creates a throwaway virtual environment under a temporary folder (``python -m venv``, then
``pip install promg``: the network is needed), starts robotale's local Neo4j in a temporary
home with APOC core and APOC extended (pinned in ``robotale/neo4j_server/plugin_jars.lock``, fetched
once from Maven Central) through ``--plugins`` and an overlay that lets APOC read the import
folder (on the ports of the configuration, ``ROBOTALE_NEO4J_BOLT_PORT`` and
``ROBOTALE_NEO4J_HTTP_PORT``, when set; else free ones), and builds in turns (robotale, PromG,
robotale, PromG ...) on an emptied database:

- with robotale: ``build_ekg`` with entities ``robot`` and ``msg_id`` and classes per
  ``activity`` (events, entities, CORR, DF, COMM, Class, OBSERVED, DF_C);
- with PromG: a semantic header that asks for the same (records, events, Robot and Message
  entities, CORR, DF, Activity nodes with OBSERVED, DF_A per entity type), driven by
  ``benchmarks/peers_promg.py`` in the virtual environment.

The logs are the thesis authors' (``examples/thesis/robotic_data.csv``, or ``--log``) and a
synthetic one of ``--synthetic`` events (``0`` skips it). For each it prints both build times,
their ratio (PromG's time over robotale's) by wall time and by CPU time (each side's process
and the Neo4j server's during its build, read from ``/proc``), the load average at each turn,
and the node and edge counts side by side. When
PromG cannot be installed or fails, it prints why and what was tried, and robotale's figures
alone.
"""

from __future__ import annotations

import argparse
import json
import os
import resource
import subprocess
import sys
import tempfile
import time
from dataclasses import dataclass
from pathlib import Path

import pandas as pd

HERE = Path(__file__).resolve().parent
THESIS_LOG = HERE.parent / "examples" / "thesis" / "robotic_data.csv"
PROMG = "promg==2.4.7"
ENTITIES = ["robot", "msg_id"]
# The overlay and apoc.conf of the benchmark's home: PromG loads its records with
# apoc.load.csv from the server's import folder, which robotale's defaults keep closed.
OVERLAY = (
    "dbms.security.procedures.unrestricted=apoc.*\n"
    "dbms.security.procedures.allowlist=apoc.*\n"
    "dbms.security.allow_csv_import_from_file_urls=true\n"
)
APOC_CONF = "apoc.import.file.enabled=true\n"
# What is compared: (row, robotale's label or type, PromG's).
ROWS = [
    ("events", "node:Event", "node:Event"),
    ("entities", "node:Entity", "node:Entity"),
    ("CORR", "relationship:CORR", "relationship:CORR"),
    ("DF", "relationship:DF", "relationship:DF"),
    ("classes", "node:Class", "node:Activity"),
    ("OBSERVED", "relationship:OBSERVED", "relationship:OBSERVED"),
    ("DF_C", "relationship:DF_C", "relationship:DF_A_*"),
]


@dataclass(frozen=True)
class Build:
    seconds: float
    counts: dict[str, int]
    version: str = ""
    #: the whole process, from its start to its exit (PromG: its import and setup included)
    process_seconds: float = 0.0
    #: CPU seconds of the side's own process during the build (robotale: this process while
    #: it builds; PromG: its driver process, from its start to its exit)
    cpu: float = 0.0
    #: CPU seconds of the Neo4j server's process during the build
    server_cpu: float = 0.0


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--log", type=Path, default=THESIS_LOG, help="a CSV event log")
    parser.add_argument("--synthetic", type=int, default=100_000, help="events (0: none)")
    parser.add_argument("--heap", default="2g", help="heap of the private Neo4j (2g)")
    parser.add_argument("--batch-size", type=int, default=10_000, help="PromG's batch size")
    parser.add_argument(
        "--repeat",
        type=int,
        default=2,
        help="builds per tool and log, the fastest counts: the first runs on a cold server (2)",
    )
    parser.add_argument(
        "--venv", type=Path, help="a virtual environment that has PromG (default: a new one)"
    )
    args = parser.parse_args()
    print(f"load average before: {os.getloadavg()[0]:.1f} on {os.cpu_count()} cores")
    with tempfile.TemporaryDirectory(prefix="robotale-peers-") as folder:
        work = Path(folder)
        if args.venv:
            python, why_not = args.venv / "bin" / "python", None
        else:
            python, why_not = promg_environment(work / "venv")
        with private_neo4j(work, args.heap) as (driver, server):
            logs = [(args.log.name, read_canonical(args.log))]
            if args.synthetic:
                logs.append((f"synthetic {args.synthetic:,}", synthetic(args.synthetic)))
            for title, log in logs:
                mine, built = [], []
                for _ in range(args.repeat):  # in turns (A B A B): both see the same machine
                    mine.append(robotale_build(driver, server, log))
                    _said("robotale", mine[-1])
                    if python is not None and (not built or built[-1] is not None):
                        build, why_not = promg_build(python, driver, server, log, work, args)
                        built.append(build)
                        if build is not None:
                            _said("PromG", build)
                done = [build for build in built if build is not None]
                report(title, len(log), fastest(mine), fastest(done) if done else None, why_not)
    print(f"load average after: {os.getloadavg()[0]:.1f}")
    return 0


# -- the two builds --------------------------------------------------------------------------


def fastest(builds) -> Build:
    return min(builds, key=lambda build: build.seconds)


def robotale_build(driver, server, log: pd.DataFrame) -> Build:
    from robotale.ekg.build import build_ekg

    clear(driver)
    served, cpu = server_cpu(server), time.process_time()
    started = time.perf_counter()
    build_ekg(driver, log, "peers", entities=ENTITIES, aggregate=["activity"], progress=False)
    seconds = time.perf_counter() - started
    cpu, served = time.process_time() - cpu, server_cpu(server) - served
    return Build(seconds, counts(driver), cpu=cpu, server_cpu=served)


def server_cpu(server) -> float:
    """CPU seconds the Neo4j server's process has used so far (0 when unknown)."""
    from robotale.timings import process_seconds

    running = server.running()
    return (process_seconds(running.pid) or 0.0) if running is not None else 0.0


def children_cpu() -> float:
    """CPU seconds of this process' children that have ended (PromG's driver process)."""
    usage = resource.getrusage(resource.RUSAGE_CHILDREN)
    return usage.ru_utime + usage.ru_stime


def ratios(ours: Build, theirs: Build) -> tuple[float, float]:
    """PromG's build over robotale's: by wall time, and by CPU time (each side's process and
    the server's during its build)."""
    wall = theirs.seconds / ours.seconds
    cpu = (theirs.cpu + theirs.server_cpu) / (ours.cpu + ours.server_cpu)
    return wall, cpu


def _said(who: str, build: Build) -> None:
    print(
        f"  turn: {who} {build.seconds:.2f} s wall, {build.cpu:.1f} s CPU "
        f"(+ Neo4j {build.server_cpu:.1f} s); load average {os.getloadavg()[0]:.1f}",
        flush=True,
    )


def promg_build(
    python: Path, driver, server, log: pd.DataFrame, work: Path, args
) -> tuple[Build | None, str | None]:
    """PromG's build of ``log`` and its counts, or None and why it failed."""
    clear(driver)
    folder = work / "promg"
    (folder / "data").mkdir(parents=True, exist_ok=True)
    promg_records(log).to_csv(folder / "data" / "log.csv", index=False)
    (folder / "header.json").write_text(json.dumps(semantic_header(), indent=2))
    (folder / "dataset.json").write_text(json.dumps(dataset_description(), indent=2))
    running = server.running()
    settings = {
        "uri": running.bolt_uri,
        "user": "neo4j",
        "password": server.password(),
        "semantic_header": str(folder / "header.json"),
        "dataset_description": str(folder / "dataset.json"),
        "aggregate_entities": ["Robot", "Message"],
        "batch_size": args.batch_size,
        "result": str(folder / "result.json"),
    }
    (folder / "settings.json").write_text(json.dumps(settings))
    (server.home / "import").mkdir(exist_ok=True)  # PromG writes its CSVs there
    served, cpu = server_cpu(server), children_cpu()
    started = time.perf_counter()
    result = subprocess.run(
        [str(python), str(HERE / "peers_promg.py"), str(folder / "settings.json")],
        cwd=folder,
        capture_output=True,
        text=True,
        check=False,
    )
    process_seconds = time.perf_counter() - started
    cpu, served = children_cpu() - cpu, server_cpu(server) - served
    if result.returncode != 0:
        # PromG reports a failed query on stdout, and Python its traceback on stderr.
        lines = result.stdout.strip().splitlines()[-6:] + result.stderr.strip().splitlines()[-3:]
        tail = "\n    ".join(lines)
        return None, f"PromG's build failed (exit {result.returncode}):\n    {tail}"
    answer = json.loads((folder / "result.json").read_text())
    found = counts(driver)
    return Build(answer["seconds"], found, answer["promg"], process_seconds, cpu, served), None


def promg_records(log: pd.DataFrame) -> pd.DataFrame:
    """The canonical log as PromG's records: one row per event, times as text APOC parses."""
    from robotale.eventlog import schema

    times = log[schema.TIMESTAMP].map(lambda t: t.isoformat(sep=" ", timespec="milliseconds"))
    return pd.DataFrame(
        {
            "eventId": log[schema.EVENT_ID].astype(str),
            "timestamp": times,
            "activity": log[schema.ACTIVITY].astype(str),
            "lifecycle": log[schema.LIFECYCLE].astype(str),
            "robot": log[schema.ROBOT].astype(str),
            "msgId": log[schema.MSG_ID],
        }
    )


def semantic_header() -> dict:
    """PromG's description of the graph robotale builds for entities robot and msg_id."""
    return {
        "name": "peers",
        "version": "1.0.0",
        "records": [
            "(record:EventRecord {eventId, timestamp, activity, lifecycle})",
            "(record:RobotRecord {robot})",
            "(record:MessageRecord {msgId})",
        ],
        "nodes": [
            _node("Event", "(record:EventRecord)", _EVENT),
            _node(
                "Activity",
                "(record:EventRecord)",
                "(a:Activity {activity: record.activity})",
                infer_observed=True,
            ),
            _entity("Robot", "RobotRecord", "record.robot"),
            _entity("Message", "MessageRecord", "record.msgId"),
        ],
        "relations": [],
    }


_EVENT = (
    "(e:Event {eventId: record.eventId, timestamp: record.timestamp, "
    "activity: record.activity, lifecycle: record.lifecycle})"
)


def _node(kind: str, record: str, result: str, **options: object) -> dict:
    constructor = {"prevalent_record": record, "result": result, **options}
    return {"type": kind, "constructor": [constructor]}


def _entity(kind: str, record: str, key: str) -> dict:
    return {
        "type": kind,
        "constructor": [
            {
                "prevalent_record": f"(record:{record})",
                "result": f"(n:Entity:{kind} {{sysId: {key}}})",
                "infer_corr_from_event_record": True,
            }
        ],
        "infer_df": True,
    }


def dataset_description() -> list[dict]:
    """How PromG reads ``data/log.csv``."""

    def attribute(name: str, optional: bool = False) -> dict:
        return {"name": name, "columns": [{"name": name, "dtype": "str"}], "optional": optional}

    timestamp = attribute("timestamp")
    # ``H`` in the format makes PromG convert to a datetime (not a date).
    timestamp["datetime_object"] = {"format": "yyyy-MM-dd HH:mm:ss.SSSXXX"}
    return [
        {
            "name": "peers",
            "file_directory": "data",
            "file_names": ["log.csv"],
            "labels": ["EventRecord", "RobotRecord", "MessageRecord"],
            "add_log": True,  # PromG transforms the records of the logs it names
            "attributes": [
                attribute("eventId"),
                timestamp,
                attribute("activity"),
                attribute("lifecycle"),
                attribute("robot"),
                attribute("msgId", optional=True),
            ],
        }
    ]


# -- PromG's virtual environment -------------------------------------------------------------


def promg_environment(folder: Path) -> tuple[Path | None, str | None]:
    """The Python of a new virtual environment with PromG, or None and what went wrong."""
    tried = []
    steps = [
        [sys.executable, "-m", "venv", str(folder)],
        [str(folder / "bin" / "python"), "-m", "pip", "install", "--quiet", PROMG],
    ]
    for step in steps:
        tried.append(" ".join(step))
        started = time.perf_counter()
        result = subprocess.run(step, capture_output=True, text=True, check=False)
        if result.returncode != 0:
            tail = "\n    ".join(result.stderr.strip().splitlines()[-6:])
            return None, f"PromG could not be installed; tried: {'; '.join(tried)}\n    {tail}"
        print(f"{step[-1] if 'pip' in step else 'venv'}: {time.perf_counter() - started:.0f} s")
    return folder / "bin" / "python", None


# -- the private server and the logs ---------------------------------------------------------


class private_neo4j:
    """A Neo4j for this benchmark only, with APOC core and extended as plugins (PromG needs
    them); with ``apoc=False`` a server as robotale sets one up for a user: no plugins, on
    free ports (so it runs beside the one with APOC)."""

    def __init__(self, work: Path, heap: str, apoc: bool = True) -> None:
        self.work, self.heap, self.apoc = work, heap, apoc

    def __enter__(self):
        from robotale.ekg.connection import Settings, connect
        from robotale.neo4j_server.jars import apoc_with_file_access
        from robotale.neo4j_server.server import LocalServer, ServerOptions, free_port

        self.work.mkdir(parents=True, exist_ok=True)
        home = self.work / "home"
        home.mkdir()
        plugins = None
        if self.apoc:
            plugins = self.work / "plugins"
            plugins.mkdir()
            for jar in apoc_with_file_access():
                (plugins / jar.name).symlink_to(jar)
            (home / "neo4j.conf").write_text(OVERLAY)
            (home / "apoc.conf").write_text(APOC_CONF)
        self.server = LocalServer(home)
        # the ports of the configuration (ROBOTALE_NEO4J_BOLT_PORT / _HTTP_PORT) when set, so
        # the benchmark runs beside a server on the default ports; else free ones
        configured = ServerOptions.from_env()
        bolt, http = (
            (configured.bolt_port, configured.http_port)
            if "ROBOTALE_NEO4J_BOLT_PORT" in os.environ and self.apoc
            else (free_port(), free_port())
        )
        options = ServerOptions(bolt, http, heap=self.heap, pagecache="1g", plugins=plugins)
        running = self.server.start(options, progress=print)
        password = self.server.password() or ""
        self.driver = connect(Settings(running.bolt_uri, "neo4j", password, True))
        return self.driver, self.server

    def __exit__(self, *exc: object) -> None:
        self.driver.close()
        self.server.stop()


def read_canonical(path: Path) -> pd.DataFrame:
    from robotale.eventlog.readers import read_log

    return read_log(path)


def synthetic(events: int) -> pd.DataFrame:
    sys.path.insert(0, str(HERE))
    from ekg_build import synthetic_log

    return synthetic_log(events)


def clear(driver) -> None:
    from robotale.queries import cypher

    with driver.session() as session:
        session.run(cypher("peers_clear")).consume()


def counts(driver) -> dict[str, int]:
    """``{"node:Event": n, "relationship:DF": m, ...}`` from Neo4j's count store: a scan of
    every relationship per type (``graph_counts``) takes minutes at a million events."""
    from robotale.queries import cypher

    with driver.session() as session:
        rows = session.run(cypher("bench_graph_counts"))
        return {f"{r['kind']}:{r['name']}": r["count"] for r in rows if r["count"]}


# -- the report ------------------------------------------------------------------------------


def report(title: str, events: int, ours: Build, theirs: Build | None, why_not: str | None) -> None:
    print(f"\n{title}: {events:,} events")
    if theirs is None:
        print(f"  robotale {ours.seconds:.2f} s; PromG: not run. {why_not}")
        _table(ours, None)
        return
    wall, cpu = ratios(ours, theirs)
    print(
        f"  robotale {ours.seconds:.2f} s wall, {ours.cpu:.1f} s CPU (+ Neo4j "
        f"{ours.server_cpu:.1f} s); PromG {theirs.version} {theirs.seconds:.2f} s wall, "
        f"{theirs.cpu:.1f} s CPU of its whole process (+ Neo4j {theirs.server_cpu:.1f} s): "
        f"ratio {wall:.1f} wall, {cpu:.1f} CPU (PromG's / robotale's; the fastest turn of each)"
    )
    _table(ours, theirs)


def _table(ours: Build, theirs: Build | None) -> None:
    print(f"  {'':10} {'robotale':>10} {'PromG':>10}")
    for row, our_key, their_key in ROWS:
        mine = _count(ours.counts, our_key)
        other = "-" if theirs is None else f"{_count(theirs.counts, their_key):,}"
        print(f"  {row:10} {mine:>10,} {other:>10}")
    if theirs is not None:
        compared = {key for _, _, key in ROWS} | {"node:Robot", "node:Message"}
        extra = {k: n for k, n in theirs.counts.items() if k not in compared}
        extra = {k: n for k, n in extra.items() if not k.startswith("relationship:DF_A_")}
        print(f"  PromG also keeps its input: {', '.join(f'{k} {n:,}' for k, n in extra.items())}")
        print(
            "  (robotale's DF stays within a case, a run; PromG's spans the whole log. "
            "PromG's DF_A leaves out self-loops, an activity directly followed by itself)"
        )


def _count(found: dict[str, int], key: str) -> int:
    if key.endswith("*"):
        return sum(n for name, n in found.items() if name.startswith(key[:-1]))
    return found.get(key, 0)


if __name__ == "__main__":
    sys.exit(main())
