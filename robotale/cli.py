"""The ``robotale`` command.

Thin by design: each ``_add_*`` function declares one command group's arguments and its handler
imports the part that does the work only when the command runs, so ``robotale --help`` stays
fast. A :class:`~robotale.errors.RobotaleError` ends the command with its one-sentence message
and exit status 1.
"""

from __future__ import annotations

import argparse
import importlib
import sys
from collections.abc import Callable, Sequence
from pathlib import Path

from robotale import __version__
from robotale.errors import RobotaleError


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog="robotale",
        description="Understand what a team of robots did: missions, event logs, EKGs.",
    )
    parser.add_argument("--version", action="version", version=f"robotale {__version__}")
    commands = parser.add_subparsers(dest="command", metavar="COMMAND")
    commands.required = True
    # One line per command group, in the order of the data flow (see DESIGN.md).
    _add_fame(commands)
    _add_simulate(commands)
    _add_prepare(commands)
    _add_neo4j(commands)
    _add_ingest(commands)
    _add_logs(commands)
    _add_serve(commands)
    _add_demo(commands)
    _add_discover(commands)
    _add_perspectives(commands)
    return parser


def _lazy(target: str) -> Callable[[argparse.Namespace], int]:
    """A handler that imports ``module.function`` only when its command runs."""
    module, _, name = target.rpartition(".")

    def handler(args: argparse.Namespace) -> int:
        return int(getattr(importlib.import_module(module), name)(args) or 0)

    return handler


def _add_neo4j(commands: argparse._SubParsersAction) -> None:
    neo4j = commands.add_parser(
        "neo4j",
        help="run a local Neo4j server (not needed when NEO4J_URI names one)",
        description="A local Neo4j 5.26 Community server on 127.0.0.1, kept under the robotale "
        "home ($ROBOTALE_HOME, default ~/.robotale). With NEO4J_URI set, robotale uses that "
        "server instead.",
    )
    actions = neo4j.add_subparsers(dest="action", metavar="ACTION", required=True)
    start = actions.add_parser("start", help="start the server in the background and wait for it")
    start.add_argument("--bolt-port", type=int, help="Bolt port (ROBOTALE_NEO4J_BOLT_PORT, 7687)")
    start.add_argument("--http-port", type=int, help="HTTP port (ROBOTALE_NEO4J_HTTP_PORT, 7474)")
    start.add_argument("--heap", help="JVM heap, e.g. 2g (ROBOTALE_NEO4J_HEAP, 1g)")
    start.add_argument("--pagecache", help="page cache, e.g. 1g (ROBOTALE_NEO4J_PAGECACHE, 512m)")
    start.add_argument("--timeout", type=float, default=180, help="seconds to wait (180)")
    start.set_defaults(handler=_lazy("robotale.ekg.commands.neo4j_start"))
    stop = actions.add_parser("stop", help="stop the server cleanly")
    stop.set_defaults(handler=_lazy("robotale.ekg.commands.neo4j_stop"))
    status = actions.add_parser("status", help="where the server is and whether it answers")
    status.set_defaults(handler=_lazy("robotale.ekg.commands.neo4j_status"))


def _add_serve(commands: argparse._SubParsersAction) -> None:
    serve = commands.add_parser(
        "serve",
        help="the dashboard at http://127.0.0.1:5000",
        description="Serve the dashboard (logs, discovery, perspectives, model, Cypher console) "
        "against the Neo4j robotale uses (NEO4J_URI, or the local server).",
    )
    serve.add_argument(
        "--host", default="127.0.0.1", help="address to listen on (127.0.0.1: this machine only)"
    )
    serve.add_argument("--port", type=int, default=5000, help="port to listen on (5000)")
    serve.add_argument("--log", help="print the address of this stored log's Discover page")
    serve.set_defaults(handler=_serve)


def _serve(args: argparse.Namespace) -> int:
    from robotale.webapp.serve import serve

    serve(host=args.host, port=args.port, log=args.log)
    return 0


def _add_fame(commands) -> None:
    fame = commands.add_parser(
        "fame",
        help="BPMN missions: check, split and run collaborations",
        description="Missions as BPMN collaborations (FAME): one pool per robot, one engine each.",
    )
    sub = fame.add_subparsers(dest="fame_command", metavar="COMMAND")
    sub.required = True
    library = {"type": Path, "metavar": "DIR", "help": "folder of .bpmn building blocks"}
    skills = {"metavar": "MODULE", "help": "Python module (or .py file) with a SKILLS mapping"}
    robots = {"metavar": "A,B", "help": "robot namespaces, e.g. drone,tractor_1,tractor_2"}

    check = sub.add_parser("check", help="structure and QoS report; exit status 1 on problems")
    check.add_argument("model", type=Path, help="the .bpmn collaboration")
    check.add_argument("--library", **library)
    check.add_argument("--skills", **skills)
    check.set_defaults(handler=_fame_check)

    split = sub.add_parser("split", help="one process per robot")
    split.add_argument("model", type=Path, help="the .bpmn collaboration")
    split.add_argument("--robots", **robots)
    split.add_argument("--out", type=Path, metavar="DIR", help="write <robot>.bpmn files here")
    split.set_defaults(handler=_fame_split)

    run = sub.add_parser("run", help="run in process on a simulated clock, printing tags")
    run.add_argument("model", type=Path, help="the .bpmn collaboration")
    run.add_argument("--robots", **robots)
    run.add_argument("--skills", **skills)
    run.add_argument("--library", **library)
    run.add_argument(
        "--until",
        type=float,
        default=3600.0,
        metavar="SECONDS",
        help="stop at this simulated time at the latest (default 3600)",
    )
    run.add_argument(
        "--latency",
        type=float,
        default=0.0,
        metavar="SECONDS",
        help="message delivery delay on the bus (default 0)",
    )
    run.add_argument(
        "--set",
        action="append",
        default=[],
        metavar="ROBOT.NAME=VALUE",
        help="an initial variable, e.g. drone.delay=10 (repeatable)",
    )
    run.set_defaults(handler=_fame_run)


def _fame_check(args: argparse.Namespace) -> int:
    from robotale.fame_runtime.commands import check_command

    return check_command(args.model, library=args.library, skills=args.skills)


def _fame_split(args: argparse.Namespace) -> int:
    from robotale.fame_runtime.commands import split_command

    return split_command(args.model, robots=args.robots, out_dir=args.out)


def _fame_run(args: argparse.Namespace) -> int:
    from robotale.fame_runtime.commands import run_command

    return run_command(
        args.model,
        robots=args.robots,
        skills=args.skills,
        library=args.library,
        until=args.until,
        latency=args.latency,
        assignments=args.set,
    )


def _add_prepare(commands) -> None:
    prepare = commands.add_parser(
        "prepare",
        help="turn rosbag2 recordings into a multi-perspective event log (CSV, XES, OCEL 2.0)",
        description="Turn a rosbag2 directory, or a folder of them (one per run), into a "
        "multi-perspective event log: every tag becomes an event enriched with the robot's "
        "position and battery, with inprogress events between each start and complete.",
    )
    prepare.add_argument("source", help="a rosbag2 directory or a folder of run directories")
    prepare.add_argument(
        "--out", metavar="CSV", help="CSV file (default: SOURCE_NAME.csv if no other output)"
    )
    prepare.add_argument("--xes", metavar="FILE", help="also write IEEE XES")
    prepare.add_argument("--ocel", metavar="FILE", help="also write OCEL 2.0 JSON")
    _add_preparation_options(prepare)
    prepare.set_defaults(handler=_lazy("robotale.ingest.commands.prepare_command"))


def _add_preparation_options(parser: argparse._ActionsContainer) -> None:
    """How recordings become an event log; shared by ``prepare`` and ``ingest``."""
    parser.add_argument(
        "--tags", default="/*/tag", metavar="GLOB", help="the tag topics (default: %(default)s)"
    )
    parser.add_argument(
        "--tag-field",
        action="append",
        default=[],
        metavar="KEY=FIELD",
        help="the tag message field holding KEY (activity, lifecycle, robot, msg_id, msg_role, "
        "payload); FIELD empty if there is none. Repeatable",
    )
    parser.add_argument(
        "--perspectives",
        default="odom,battery",
        metavar="LIST",
        help="comma-separated: odom, battery, NAME=/TOPIC_GLOB:FIELD (default: %(default)s)",
    )
    parser.add_argument(
        "--rate",
        type=float,
        default=1.0,
        metavar="HZ",
        help="inprogress events per second of an activity, 0 for none (default: %(default)s)",
    )
    parser.add_argument(
        "--msg",
        action="append",
        default=[],
        metavar="PATH",
        help="a .msg/.idl file or a folder of them, for types the bags do not define. Repeatable",
    )
    parser.add_argument(
        "--bag-time",
        action="store_true",
        help="time events by when the bag recorded them, not by their message stamps",
    )


def _add_ingest(commands: argparse._SubParsersAction) -> None:
    ingest = commands.add_parser(
        "ingest",
        help="load an event log (CSV, XES or rosbag2 recordings) into Neo4j as an event "
        "knowledge graph",
        description="Read an event log, or prepare one from rosbag2 recordings as `robotale "
        "prepare` does, and store it in Neo4j: Event, Entity and Class nodes, CORR, DF, COMM, "
        "OBSERVED and DF_C edges. Nothing is written if the log is refused, and a failed ingest "
        "leaves the database as it was.",
    )
    ingest.add_argument(
        "path", help="a .csv or .xes event log, a rosbag2 directory or a folder of runs"
    )
    ingest.add_argument(
        "--log", help="name of the log in Neo4j (default: the file's or folder's name)"
    )
    ingest.add_argument(
        "--entities",
        help="comma-separated columns whose values are entities (default: robot,msg_id "
        "where present, else case); a cell may hold several ids separated by commas",
    )
    ingest.add_argument(
        "--aggregate",
        action="append",
        metavar="KEY",
        help="an aggregation key: activity, or activity plus entity columns such as "
        "activity,robot; repeat for several (default: activity)",
    )
    ingest.add_argument(
        "--map",
        action="append",
        default=[],
        metavar="COLUMN=FIELD",
        help="read COLUMN as FIELD (time, activity, case, robot, lifecycle, msg_id ...); "
        "repeatable",
    )
    ingest.add_argument("--case", metavar="COLUMN", help="the column that tells cases apart")
    ingest.add_argument("--replace", action="store_true", help="rebuild a log that exists")
    _add_preparation_options(ingest.add_argument_group("recordings (rosbag2 directories)"))
    ingest.set_defaults(handler=_lazy("robotale.ekg.log_commands.ingest"))


def _add_logs(commands: argparse._SubParsersAction) -> None:
    logs = commands.add_parser("logs", help="the event logs stored in Neo4j")
    actions = logs.add_subparsers(dest="action", metavar="ACTION", required=True)
    actions.add_parser("list", help="every stored log").set_defaults(
        handler=_lazy("robotale.ekg.log_commands.logs_list")
    )
    show = actions.add_parser("show", help="what one log holds, counted in the graph")
    show.add_argument("name")
    show.set_defaults(handler=_lazy("robotale.ekg.log_commands.logs_show"))
    delete = actions.add_parser("delete", help="remove a log and everything of it")
    delete.add_argument("name")
    delete.set_defaults(handler=_lazy("robotale.ekg.log_commands.logs_delete"))


def _add_demo(commands: argparse._SubParsersAction) -> None:
    demo = commands.add_parser(
        "demo",
        help="the whole mission end to end: simulate, prepare, ingest, serve the dashboard",
        description="Starts the local Neo4j (unless NEO4J_URI names a server), simulates the "
        "agri mission (drone + two tractors), prepares its bags into an event log, ingests it "
        "as the log 'agri' and the thesis' own log as 'thesis' (replacing earlier ones), "
        "attaches the BPMN models and serves the dashboard until Ctrl-C.",
    )
    demo.add_argument(
        "--runs",
        type=int,
        metavar="N",
        help="runs to simulate (default: $ROBOTALE_DEMO_RUNS, else 20)",
    )
    demo.add_argument("--seed", type=int, default=1, help="seed of the runs (default: 1)")
    demo.add_argument(
        "--out", metavar="DIR", help="folder for the bags and the CSV (default: ~/.robotale/demo)"
    )
    demo.add_argument("--port", type=int, default=5000, help="the dashboard's port (5000)")
    demo.add_argument(
        "--no-serve", action="store_true", help="stop after ingesting instead of serving"
    )
    demo.set_defaults(handler=_lazy("robotale.demo.demo"))


def _add_simulate(commands) -> None:
    simulate = commands.add_parser(
        "simulate",
        help="run missions with simulated robots (pybullet), one rosbag2 per run",
        description="Simulated robots carry out a BPMN mission, each run recorded as a rosbag2 "
        "directory (<out>/run_0001/ ...) with a robotale-run.json manifest. Scenarios: agri "
        "(drone + tractors, thesis ch. 3) and rexdingo (thesis 5.3); or your own --model with a "
        "--world file.",
    )
    simulate.add_argument("scenario", nargs="?", help="agri or rexdingo (or omit with --world)")
    simulate.add_argument("--model", type=Path, metavar="BPMN", help="the mission to run instead")
    simulate.add_argument("--world", type=Path, metavar="YAML", help="a world file of your own")
    simulate.add_argument("--runs", type=int, default=1, metavar="N", help="how many runs (1)")
    simulate.add_argument("--seed", type=int, default=1, help="the batch's seed (1)")
    simulate.add_argument(
        "--first", type=int, default=1, metavar="N", help="number of the first run (1)"
    )
    simulate.add_argument("--out", metavar="DIR", help="where the runs go (runs/<scenario>)")
    simulate.add_argument("--tractors", type=int, metavar="N", help="agri: how many tractors")
    simulate.add_argument(
        "--count",
        action="append",
        default=[],
        metavar="GROUP=N",
        help="robots of a group, e.g. tractor=3 (repeatable)",
    )
    simulate.add_argument("--weeds", metavar="N|LOW-HIGH", help="weeds per run, e.g. 2 or 3-6")
    simulate.add_argument(
        "--fault",
        action="append",
        default=[],
        metavar="SPEC",
        help="die:ROBOT@T, drop:/TOPIC[,to=ROBOT][,nth=N], battery:ROBOT@T[,rate=R][,for=S]; "
        "@FROM-TO and ,p=P vary it per run (repeatable)",
    )
    simulate.add_argument(
        "--storage", choices=("sqlite3", "mcap"), default="sqlite3", help="bag storage (sqlite3)"
    )
    simulate.add_argument(
        "--rate", type=float, metavar="HZ", help="odometry and battery samples a second (2)"
    )
    simulate.add_argument("--topics", metavar="A,B", help="also record these robot topics")
    simulate.add_argument("--time-limit", type=float, metavar="SECONDS", help="per run (900)")
    simulate.add_argument(
        "--workers", type=int, metavar="N", help="worker processes (one per CPU); 0: none"
    )
    simulate.add_argument("--gui", action="store_true", help="watch in pybullet's window")
    simulate.add_argument(
        "--pace", type=float, metavar="X", help="simulated seconds per wall second (--gui: 1)"
    )
    simulate.add_argument("--overwrite", action="store_true", help="replace runs already in --out")
    simulate.add_argument("--quiet", action="store_true", help="no progress bar")
    simulate.set_defaults(handler=_lazy("robotale.sim.commands.simulate_command"))


def _add_log_source(parser: argparse.ArgumentParser, stored: bool = False) -> None:
    """The event log a discovery or perspectives command reads."""
    parser.add_argument("log", nargs="?", help="event log file (.csv or .xes)")
    if stored:
        parser.add_argument("--log", dest="log_name", metavar="NAME", help="a log stored in Neo4j")
    parser.add_argument(
        "--map",
        action="append",
        default=[],
        metavar="COLUMN=FIELD",
        help="read COLUMN as FIELD (time, activity, case, robot ...). Repeatable",
    )
    parser.add_argument(
        "--case-column", metavar="COLUMN", help="the column telling runs apart (default: case)"
    )


def _add_discover(commands: argparse._SubParsersAction) -> None:
    discover = commands.add_parser(
        "discover",
        help="process models from a log: DFG, aggregated EKG, conformance to a BPMN model",
        description="Discover process models from an event log (thesis 7.1.2).",
    )
    actions = discover.add_subparsers(dest="action", metavar="ACTION", required=True)
    graph_output = {
        "--out": {"metavar": "JSON", "help": "write the graph as JSON (default: print it)"},
        "--svg": {"metavar": "SVG", "help": "draw the graph (needs Graphviz's dot)"},
    }

    dfg = actions.add_parser("dfg", help="directly-follows graph (pm4py)")
    _add_log_source(dfg)
    for flag, text in (
        ("--case", "keep these cases (runs)"),
        ("--robot", "keep these robots"),
        ("--robot-type", "keep these robot types (pools)"),
        ("--activity", "keep these activities"),
    ):
        dfg.add_argument(flag, action="append", metavar="A,B", help=f"{text}. Repeatable")
    dfg.add_argument("--since", metavar="TIME", help="keep events at or after this ISO time")
    dfg.add_argument("--until", metavar="TIME", help="keep events at or before this ISO time")
    _add_graph_output(dfg, graph_output)
    dfg.set_defaults(handler=_lazy("robotale.discovery.commands.discover_dfg"))

    ekg = actions.add_parser("ekg", help="aggregated event knowledge graph from Neo4j")
    ekg.add_argument("--log", dest="log_name", required=True, metavar="NAME", help="stored log")
    ekg.add_argument(
        "--aggregate",
        default="activity,robot",
        metavar="KEYS",
        help="event properties a class is made of (default: %(default)s)",
    )
    ekg.add_argument(
        "--entities", metavar="TYPES", help="entity types whose DF_C edges to show (default: all)"
    )
    _add_graph_output(ekg, graph_output)
    ekg.set_defaults(handler=_lazy("robotale.discovery.commands.discover_ekg"))

    conformance = actions.add_parser(
        "conformance", help="replay each robot against its pool of a BPMN collaboration"
    )
    _add_log_source(conformance)
    conformance.add_argument("--model", required=True, type=Path, help="the .bpmn collaboration")
    conformance.add_argument("--library", type=Path, metavar="DIR", help="building blocks")
    conformance.add_argument("--json", metavar="FILE", help="also write the report as JSON")
    conformance.set_defaults(handler=_lazy("robotale.discovery.commands.discover_conformance"))


def _add_graph_output(parser: argparse.ArgumentParser, options: dict) -> None:
    for flag, keywords in options.items():
        parser.add_argument(flag, **keywords)
    parser.add_argument(
        "--labels",
        choices=("frequency", "performance"),
        default="frequency",
        help="what the SVG's edges show (default: %(default)s)",
    )


def _add_perspectives(commands: argparse._SubParsersAction) -> None:
    perspectives = commands.add_parser(
        "perspectives",
        help="spatial, communication, battery, performance perspectives and bottlenecks",
        description="Enhance the process with the log's perspectives (thesis 6.2.2, 7.2.2): "
        "an HTML report (works offline) and/or JSON.",
    )
    _add_log_source(perspectives, stored=True)
    perspectives.add_argument("--out", metavar="HTML", help="write the report as HTML")
    perspectives.add_argument("--json", metavar="JSON", help="write the report as JSON")
    perspectives.add_argument("--activity", help="only this activity (drill-down)")
    perspectives.add_argument("--robot", help="only this robot (drill-down)")
    perspectives.add_argument(
        "--field",
        metavar="X0,X1,Y0,Y1[,CELL]",
        help="the field to measure coverage of, e.g. 0,10,0,10 (cells of 1 m by default)",
    )
    perspectives.add_argument(
        "--threshold",
        type=float,
        default=20.0,
        metavar="PERCENT",
        help="battery level counted as low (default: %(default)s)",
    )
    perspectives.set_defaults(handler=_lazy("robotale.enhancement.commands.perspectives"))


def main(argv: Sequence[str] | None = None) -> int:
    args = build_parser().parse_args(argv)
    try:
        return int(args.handler(args) or 0)
    except RobotaleError as error:
        print(f"robotale: {error}", file=sys.stderr)
        return 1
    except KeyboardInterrupt:
        print("robotale: interrupted", file=sys.stderr)
        return 130
