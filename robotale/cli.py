"""The ``robotale`` command.

Declarations only: each ``_add_*`` function declares one command group's arguments, with
``dest`` names equal to the keyword arguments of its handler in :mod:`robotale.commands`. The
handler's module is imported only when its command runs, so ``robotale --help`` stays fast. An
option the user did not give is not passed at all (its default is ``None`` here), so the
handler, or the library below it, owns the default. A :class:`~robotale.errors.RobotaleError`
ends the command with its one-sentence message and exit status 1.
"""

from __future__ import annotations

import argparse
import importlib
import sys
from collections.abc import Iterator, Sequence
from pathlib import Path

from robotale import __version__
from robotale.errors import RobotaleError
from robotale.extras import require
from robotale.thresholds import LOW_BATTERY_PERCENT, MESSAGE_TIMEOUT
from robotale.timings import stage

#: the namespace key holding the handler's dotted name; subparser keys begin with "_" too
_HANDLER = "_handler"
_EXTRA = "_extra"


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog="robotale",
        description="Understand what a team of robots did: missions, event logs, EKGs.",
    )
    parser.add_argument("--version", action="version", version=f"robotale {__version__}")
    commands = parser.add_subparsers(dest="_command", metavar="COMMAND")
    commands.required = True
    # One line per command group, in the order of the data flow (see docs/architecture.md).
    _add_fame(commands)
    _add_record(commands)
    _add_monitor(commands)
    _add_simulate(commands)
    _add_prepare(commands)
    _add_annotate(commands)
    _add_neo4j(commands)
    _add_inspect(commands)
    _add_ingest(commands)
    _add_logs(commands)
    _add_serve(commands)
    _add_demo(commands)
    _add_aggregate(commands)
    _add_discover(commands)
    _add_perspectives(commands)
    _add_report(commands)
    _add_compare(commands)
    return parser


class _Registered:
    """The choices of an option, read from their registry when an option is checked (so
    ``robotale --help`` never imports it): ``where`` names a function giving the names."""

    def __init__(self, where: str) -> None:
        self.where = where

    def _names(self) -> Sequence[str]:
        module, _, function = self.where.rpartition(".")
        return getattr(importlib.import_module(module), function)()

    def __contains__(self, name: object) -> bool:
        return name in self._names()

    def __iter__(self) -> Iterator[str]:
        return iter(self._names())


def _handled_by(parser: argparse.ArgumentParser, target: str, *, extra: str = "") -> None:
    """``target`` (``module.function`` below ``robotale.commands``) handles ``parser``; its
    module needs the optional ``extra`` installed."""
    parser.set_defaults(**{_HANDLER: f"robotale.commands.{target}", _EXTRA: extra})


def run_handler(args: argparse.Namespace) -> int:
    """Import the command's handler and call it with the arguments the user gave."""
    module, _, name = getattr(args, _HANDLER).rpartition(".")
    if getattr(args, _EXTRA, ""):
        require(getattr(args, _EXTRA))
    with stage("import the command's modules"):
        handler = getattr(importlib.import_module(module), name)
    given = {k: v for k, v in vars(args).items() if not k.startswith("_") and v is not None}
    with stage(f"the command {name}"):
        return int(handler(**given) or 0)


def _add_neo4j(commands: argparse._SubParsersAction) -> None:
    neo4j = commands.add_parser(
        "neo4j",
        help="run a local Neo4j server (not needed when NEO4J_URI names one)",
        description="A local Neo4j Community server (5.26 LTS, or a newer release with "
        "--version) on 127.0.0.1, kept under the robotale home ($ROBOTALE_HOME, default "
        "~/.robotale). With NEO4J_URI set, robotale uses that server instead.",
    )
    actions = neo4j.add_subparsers(dest="_action", metavar="ACTION", required=True)
    start = actions.add_parser("start", help="start the server in the background and wait for it")
    start.add_argument("--bolt-port", type=int, help="Bolt port (ROBOTALE_NEO4J_BOLT_PORT, 7687)")
    start.add_argument("--http-port", type=int, help="HTTP port (ROBOTALE_NEO4J_HTTP_PORT, 7474)")
    start.add_argument("--heap", help="JVM heap, e.g. 2g (ROBOTALE_NEO4J_HEAP, 1g)")
    start.add_argument("--pagecache", help="page cache, e.g. 1g (ROBOTALE_NEO4J_PAGECACHE, 512m)")
    start.add_argument(
        "--plugins",
        metavar="DIR",
        help="folder of plugin jars such as APOC (ROBOTALE_NEO4J_PLUGINS; default: the "
        "plugins folder of the robotale home, when there is one)",
    )
    start.add_argument(
        "--version",
        help="the Neo4j release line or version, e.g. 2026.08 (ROBOTALE_NEO4J_VERSION; default "
        "the LTS line; an unknown one is refused naming those offered); a home's data stays "
        "with the release that wrote it",
    )
    start.add_argument("--timeout", type=float, help="seconds to wait (180)")
    _handled_by(start, "neo4j.neo4j_start")
    stop = actions.add_parser("stop", help="stop the server cleanly")
    _handled_by(stop, "neo4j.neo4j_stop")
    status = actions.add_parser("status", help="where the server is and whether it answers")
    _handled_by(status, "neo4j.neo4j_status")


def _add_serve(commands: argparse._SubParsersAction) -> None:
    serve = commands.add_parser(
        "serve",
        help="the dashboard at http://127.0.0.1:5000",
        description="Serve the dashboard (logs, discovery, perspectives, model, Cypher console) "
        "against the Neo4j robotale uses (NEO4J_URI, or the local server).",
    )
    serve.add_argument("--host", help="address to listen on (127.0.0.1: this machine only)")
    serve.add_argument("--port", type=int, help="port to listen on (5000)")
    serve.add_argument("--log", help="print the address of this stored log's Discover page")
    serve.add_argument(
        "--bag",
        type=Path,
        metavar="DIR",
        help="replay this rosbag2 recording (a run folder, or a folder of runs) on the "
        "Mission page without storing it",
    )
    _handled_by(serve, "serve.serve_command")


def _add_fame(commands: argparse._SubParsersAction) -> None:
    fame = commands.add_parser(
        "fame",
        help="BPMN missions: check, split and run collaborations",
        description="Missions as BPMN collaborations (FAME): one pool per robot, one engine each.",
    )
    sub = fame.add_subparsers(dest="_fame_command", metavar="COMMAND")
    sub.required = True
    library = {"type": Path, "metavar": "DIR", "help": "folder of .bpmn building blocks"}
    skills = {"metavar": "MODULE", "help": "Python module (or .py file) with a SKILLS mapping"}
    robots = {"metavar": "A,B", "help": "robot namespaces, e.g. drone,tractor_1,tractor_2"}

    check = sub.add_parser("check", help="structure and QoS report; exit status 1 on problems")
    check.add_argument("model", type=Path, help="the .bpmn collaboration")
    check.add_argument("--library", **library)
    check.add_argument("--skills", **skills)
    check.add_argument(
        "--world",
        type=Path,
        metavar="YAML",
        help="a simulation's world file: check call activities against its skills (unless "
        "--skills) and list what its robots do not provide",
    )
    check.add_argument(
        "--json",
        dest="as_json",
        action="store_true",
        default=None,
        help="the report as JSON (each problem with element, file, line, column, sentence)",
    )
    _handled_by(check, "fame.check_command")

    split = sub.add_parser("split", help="one process per robot")
    split.add_argument("model", type=Path, help="the .bpmn collaboration")
    split.add_argument("--robots", **robots)
    split.add_argument(
        "--out", dest="out_dir", type=Path, metavar="DIR", help="write <robot>.bpmn files here"
    )
    _handled_by(split, "fame.split_command")

    run = sub.add_parser("run", help="run a mission (simulated, or one process per robot)")
    run.add_argument("model", type=Path, help="the .bpmn collaboration")
    run.add_argument("--robots", **robots)
    run.add_argument("--skills", **skills)
    run.add_argument("--library", **library)
    run.add_argument(
        "--until",
        type=float,
        metavar="SECONDS",
        help="stop this many seconds after the start at the latest (default 3600)",
    )
    run.add_argument(
        "--start",
        metavar="ISO",
        help="the clock's start, e.g. 2024-05-01T08:00:00Z (default: now)",
    )
    run.add_argument(
        "--bus",
        choices=("inprocess", "dds"),
        help="inprocess (default): one process, simulated clock; dds: one process per robot "
        "over Cyclone DDS (ROS 2 topics) on the wall clock",
    )
    run.add_argument(
        "--record",
        type=Path,
        metavar="DIR",
        help="with --bus dds: record the tags and signals into this rosbag2 folder",
    )
    run.add_argument(
        "--latency",
        type=float,
        metavar="SECONDS",
        help="message delivery delay on the bus (default 0)",
    )
    run.add_argument(
        "--set",
        dest="assignments",
        action="append",
        metavar="ROBOT.NAME=VALUE",
        help="an initial variable, e.g. drone.delay=10 (repeatable)",
    )
    _handled_by(run, "fame.run_command")

    verify = sub.add_parser(
        "verify",
        help="model analysis before anything runs; exit status 1 on a finding, 2 on bad input",
        description="Explore the mission's states (one engine per robot, signals broadcast, "
        "timers and unknown conditions as choices) and report deadlocks, lost signals, "
        "catches that never fire, elements never reached and loops without exit, each with "
        "a shortest trace.",
    )
    verify.add_argument("model", type=Path, help="the .bpmn collaboration")
    verify.add_argument("--robots", **robots)
    verify.add_argument("--skills", **skills)
    verify.add_argument("--library", **library)
    verify.add_argument(
        "--outside",
        metavar="A,B",
        help="signals and errors the world raises at any time (a camera, a skill, a battery "
        "monitor), e.g. weed_found,low_battery",
    )
    verify.add_argument(
        "--max-states", type=int, metavar="N", help="stop after this many states (200000)"
    )
    verify.add_argument(
        "--timeout", type=float, metavar="SECONDS", help="stop after this long (60)"
    )
    verify.add_argument("--json", dest="as_json", action="store_true", default=None)
    _handled_by(verify, "fame_verify.verify_command")

    node = sub.add_parser(
        "node",
        help="run one robot's engine in this process over DDS (on that robot's machine)",
        description="One robot's engine on Cyclone DDS (ROS_DOMAIN_ID, CYCLONEDDS_URI): it "
        "waits for the mission's other robots, runs until every robot is idle, publishes its "
        "tags on /<robot>/tag. Ctrl-C runs the robot's safe-state handler first.",
    )
    node.add_argument("model", type=Path, help="the .bpmn collaboration")
    node.add_argument("--robot", required=True, help="the robot this process runs")
    node.add_argument("--robots", **robots)
    node.add_argument("--skills", **skills)
    node.add_argument("--library", **library)
    node.add_argument(
        "--until", type=float, metavar="SECONDS", help="stop this long after the start (3600)"
    )
    node.add_argument("--start", metavar="ISO", help="the clock's start (default: now)")
    node.add_argument(
        "--wait", type=float, metavar="SECONDS", help="how long to wait for the others (30)"
    )
    node.add_argument(
        "--set",
        dest="assignments",
        action="append",
        metavar="ROBOT.NAME=VALUE",
        help="an initial variable (repeatable)",
    )
    # set by `fame run --bus dds` for the processes it starts
    node.add_argument("--clock-offset", type=float, help=argparse.SUPPRESS)
    node.add_argument("--origin", type=float, help=argparse.SUPPRESS)
    node.add_argument(
        "--wait-for-recorder",
        dest="recorder",
        action="store_const",
        const=True,
        help=argparse.SUPPRESS,
    )
    _handled_by(node, "fame_dds.node_command", extra="dds")


def _add_record(commands: argparse._SubParsersAction) -> None:
    record = commands.add_parser(
        "record",
        help="record live ROS 2 topics (tags, signals, odometry ...) into a rosbag2",
        description="Record every topic with a ROS 2 type robotale knows on the DDS domain "
        "(ROS_DOMAIN_ID) into a rosbag2 folder until Ctrl-C or --duration.",
    )
    record.add_argument("out_dir", type=Path, metavar="DIR", help="the bag folder to create")
    record.add_argument(
        "--robots", required=True, help="the robots' namespaces, e.g. drone,tractor_1"
    )
    record.add_argument("--duration", type=float, metavar="SECONDS", help="stop after this long")
    _handled_by(record, "fame_dds.record_command", extra="dds")


def _add_monitor(commands: argparse._SubParsersAction) -> None:
    monitor = commands.add_parser(
        "monitor",
        help="watch live robots over DDS: their tags stored in Neo4j as they come, alerts",
        description="Subscribe to the mission's robots' tags on the DDS domain (ROS_DOMAIN_ID), "
        "store each in Neo4j as it arrives under --log, print it, and raise an alert (printed, "
        "stored, published on /robotale/alerts) when a robot does what its pool does not "
        "allow, is silent too long, or its battery falls below the threshold.",
    )
    monitor.add_argument("model", type=Path, metavar="MISSION.bpmn")
    monitor.add_argument("--robots", help="the robots' namespaces, e.g. drone,tractor_1")
    monitor.add_argument("--log", required=True, help="the name the live run is stored under")
    _add_alert_limits(monitor)
    monitor.add_argument("--duration", type=float, metavar="SECONDS", help="stop after this long")
    _handled_by(monitor, "monitor.monitor_command", extra="dds")


def _add_alert_limits(parser: argparse.ArgumentParser) -> None:
    """When the monitor of a live run (``monitor``, ``simulate --live``) raises alerts."""
    parser.add_argument(
        "--silence",
        type=float,
        metavar="SECONDS",
        help="alert when a robot says nothing this long (default 10)",
    )
    parser.add_argument(
        "--battery",
        type=float,
        metavar="PERCENT",
        help=f"alert below this charge (default {LOW_BATTERY_PERCENT:g})",
    )
    parser.add_argument(
        "--message-timeout",
        action="append",
        metavar="[TYPE=]SECONDS",
        help="alert when a message (of the type: its send's label) is not received within "
        f"this long (default {MESSAGE_TIMEOUT:g}); repeatable",
    )
    parser.add_argument(
        "--durations-from",
        action="append",
        metavar="LOG",
        help="alert when an activity runs longer than the 95th percentile of its durations "
        "in this stored log (earlier runs of the mission); repeatable",
    )


def _add_prepare(commands: argparse._SubParsersAction) -> None:
    prepare = commands.add_parser(
        "prepare",
        help="turn rosbag2 recordings into a multi-perspective event log (CSV, XES, OCEL 2.0)",
        description="Turn a rosbag2 directory, or a folder of them (one per run), into a "
        "multi-perspective event log: every tag becomes an event enriched with the robot's "
        "position and battery, with inprogress events between each start and complete.",
    )
    prepare.add_argument(
        "source", type=Path, help="a rosbag2 directory or a folder of run directories"
    )
    prepare.add_argument(
        "--out",
        metavar="CSV|DATASET.parquet",
        help="CSV file, or with .parquet a Parquet dataset partitioned by run; a path or an "
        "fsspec URL (default: SOURCE_NAME.csv if no other output)",
    )
    prepare.add_argument("--xes", type=Path, metavar="FILE", help="also write IEEE XES")
    prepare.add_argument("--ocel", type=Path, metavar="FILE", help="also write OCEL 2.0 JSON")
    _add_preparation_options(prepare)
    _add_executor(prepare)
    _handled_by(prepare, "prepare.prepare_command")


def _add_annotate(commands: argparse._SubParsersAction) -> None:
    annotate = commands.add_parser(
        "annotate",
        help="copy recordings as MCAP with their activities, messages and findings added",
        description="Copy a rosbag2 directory, or each run of a folder of them, as an MCAP "
        "rosbag2 directory under --out with added topics: each robot's current activity "
        "(/robotale/<robot>/activity, std_msgs/String, and activity_index, std_msgs/Int32) "
        "and, on /robotale/log (rcl_interfaces/Log), every message exchange, lost message, "
        "bottleneck instance and, with --model, deviation from the model. The original "
        "messages are copied byte for byte. Open it in Foxglove, Lichtblick or PlotJuggler "
        "(docs/annotate.md).",
    )
    annotate.add_argument(
        "source", type=Path, help="a rosbag2 directory or a folder of run directories"
    )
    annotate.add_argument(
        "--out", type=Path, required=True, metavar="DIR", help="the folder the copies go to"
    )
    annotate.add_argument(
        "--model", type=Path, metavar="BPMN", help="a BPMN collaboration to check the runs against"
    )
    _add_preparation_options(annotate)
    _handled_by(annotate, "annotate.annotate_command")


def _add_executor(parser: argparse.ArgumentParser) -> None:
    parser.add_argument(
        "--executor",
        dest="executor",
        default=None,
        metavar="local[:N]|dask://HOST:PORT",
        help="where the runs go: a local process pool (N processes) or the scheduler of a "
        "Dask cluster whose workers reach the bags at the same path (docs/scale.md)",
    )


def _add_preparation_options(parser: argparse._ActionsContainer) -> None:
    """How recordings become an event log; shared by ``prepare``, ``ingest`` and ``annotate``.
    Each ``dest`` is a field of :class:`~robotale.eventlog.options.PrepareOptions` (but
    ``skip_bad``, which says what to do with a run that cannot be read)."""
    parser.add_argument(
        "--skip-bad",
        dest="skip_bad",
        action="store_true",
        default=None,
        help="leave out a run that cannot be read (named, with why) and keep the others; "
        "without it such a run stops everything before anything is written",
    )
    parser.add_argument("--tags", metavar="GLOB", help="the tag topics (default: /*/tag)")
    parser.add_argument(
        "--tag-field",
        dest="tag_fields",
        action="append",
        metavar="KEY=FIELD",
        help="the tag message field holding KEY (activity, lifecycle, robot, msg_id, msg_role, "
        "payload); FIELD empty if there is none. Repeatable",
    )
    parser.add_argument(
        "--perspectives",
        metavar="LIST",
        help="comma-separated: odom, battery, NAME=/TOPIC_GLOB:FIELD (default: odom,battery)",
    )
    parser.add_argument(
        "--rate",
        type=float,
        metavar="HZ",
        help="inprogress events per second of an activity, 0 for none (default: 1.0)",
    )
    parser.add_argument(
        "--msg",
        dest="msg_files",
        action="append",
        metavar="PATH",
        help="a .msg/.srv/.action/.idl file or a folder of them, for types the bags do not "
        "define. Repeatable",
    )
    parser.add_argument(
        "--bag-time",
        action="store_true",
        default=None,
        help="time events by when the bag recorded them, not by their message stamps",
    )
    parser.add_argument(
        "--lifecycle",
        choices=("explicit", "implicit", "events"),
        default=None,
        help="how tags end activities: their lifecycle field (explicit), the robot's next tag "
        "(implicit), or not at all (events); default: explicit, events for tags without one",
    )
    parser.add_argument(
        "--actions",
        metavar="GLOB",
        default=None,
        help="ROS 2 action status topics whose goals are activities, e.g. /*/_action/status",
    )
    parser.add_argument(
        "--state-topic",
        dest="states",
        action="append",
        default=None,
        metavar="GLOB[:FIELD]",
        help="a string or enum topic whose values are activities, e.g. /*/mode. Repeatable",
    )
    parser.add_argument(
        "--bt-log",
        dest="bt_logs",
        metavar="GLOB",
        default=None,
        help="behaviour-tree transition logs whose nodes are activities, e.g. /behavior_tree_log",
    )
    parser.add_argument(
        "--robot",
        metavar="NAME",
        default=None,
        help="the robot of tags and activities on topics without a namespace "
        "(default: the bag's only namespace, else robot)",
    )
    parser.add_argument(
        "--auto",
        action="store_true",
        default=None,
        help="also take activities from whatever actions, state topics and BT logs a bag holds, "
        "and say what was chosen",
    )
    parser.add_argument(
        "--distro",
        choices=("humble", "iron", "jazzy"),
        default=None,
        help="the ROS 2 distribution whose standard message types fill in those the bags do "
        "not define (default: the one a bag names, else humble)",
    )


def _add_ingest(commands: argparse._SubParsersAction) -> None:
    ingest = commands.add_parser(
        "ingest",
        help="load an event log (CSV, XES, OCEL 2.0 or rosbag2 recordings) into Neo4j as an "
        "event knowledge graph",
        description="Read an event log, or prepare one from rosbag2 recordings as `robotale "
        "prepare` does, and store it in Neo4j: Event, Entity and Class nodes, CORR, DF, COMM, "
        "OBSERVED and DF_C edges. Nothing is written if the log is refused, and a failed ingest "
        "leaves the database as it was.",
    )
    ingest.add_argument(
        "path",
        type=Path,
        help="a .csv or .xes event log, an OCEL 2.0 log (.jsonocel/.json, .xmlocel/.xml, "
        ".sqlite/.db), a rosbag2 directory or a folder of runs",
    )
    ingest.add_argument(
        "--objects",
        type=Path,
        metavar="DIR",
        help="a CSV log's object tables: DIR/<Type>.csv with an id column and one column per "
        "attribute, for the events' column <Type> (object ids, several comma-separated)",
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
        "activity,robot; repeat for several (default: activity, and activity,robot when "
        "robots are entities, as the dashboard builds an upload)",
    )
    _add_mapping(ingest)
    ingest.add_argument("--case", metavar="COLUMN", help="the column that tells cases apart")
    _add_case_gap(ingest)
    ingest.add_argument(
        "--replace", action="store_true", default=None, help="rebuild a log that exists"
    )
    ingest.add_argument(
        "--append",
        action="store_true",
        default=None,
        help="add new runs (cases), or an object-centric log's new events, to a log that exists",
    )
    ingest.add_argument(
        "--build",
        metavar="HOW",
        help="how the graph is written: online (Cypher batches, any server), bulk (Neo4j's "
        "offline importer: only into an empty database of robotale's own local server, which "
        "is stopped and started again meanwhile), or auto (the default: bulk for a large log "
        "where it can be used, else online)",
    )
    ingest.add_argument(
        "--pages",
        metavar="WHEN",
        default=None,
        help="when the dashboard's first pages of the log are prepared: by a process of its "
        "own after the command ends (background, the default, or $ROBOTALE_PAGES), before it "
        "ends (now), or on their first visit (visit)",
    )
    _add_preparation_options(ingest.add_argument_group("recordings (rosbag2 directories)"))
    _handled_by(ingest, "ingest.ingest_command")


def _add_mapping(parser: argparse.ArgumentParser) -> None:
    parser.add_argument(
        "--map",
        dest="mapping",
        action="append",
        metavar="COLUMN=FIELD",
        help="read COLUMN as FIELD (time, activity, case, robot, lifecycle, msg_id ...); "
        "repeatable",
    )


def _add_logs(commands: argparse._SubParsersAction) -> None:
    logs = commands.add_parser("logs", help="the event logs stored in Neo4j")
    actions = logs.add_subparsers(dest="_action", metavar="ACTION", required=True)
    _handled_by(actions.add_parser("list", help="every stored log"), "ingest.logs_list")
    show = actions.add_parser("show", help="what one log holds, counted in the graph")
    show.add_argument("name")
    _handled_by(show, "ingest.logs_show")
    delete = actions.add_parser("delete", help="remove a log and everything of it")
    delete.add_argument("name")
    _handled_by(delete, "ingest.logs_delete")


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
    demo.add_argument("--seed", type=int, help="seed of the runs (default: 1)")
    demo.add_argument(
        "--out",
        type=Path,
        metavar="DIR",
        help="folder for the bags and the CSV (default: ~/.robotale/demo)",
    )
    demo.add_argument("--port", type=int, help="the dashboard's port (5000)")
    demo.add_argument(
        "--no-serve",
        dest="serve",
        action="store_false",
        default=None,
        help="stop after ingesting instead of serving",
    )
    _handled_by(demo, "demo.demo_command")


def _add_simulate(commands: argparse._SubParsersAction) -> None:
    simulate = commands.add_parser(
        "simulate",
        help="run missions with simulated robots (pybullet), one rosbag2 per run",
        description="Simulated robots carry out a BPMN mission, each run recorded as a rosbag2 "
        "directory (<out>/run_0001/ ...) with a robotale-run.json manifest. Scenarios: agri "
        "(drone + tractors, thesis ch. 3), rexdingo (thesis 5.3) and stop (the stop-distance "
        "experiment of 5.3.5: FAME against direct code at 0.8, 0.9, 1.0 m/s, with its table); "
        "or your own --model with a --world file.",
    )
    simulate.add_argument(
        "scenario", nargs="?", help="agri, rexdingo or stop (or omit with --world)"
    )
    simulate.add_argument("--model", type=Path, metavar="BPMN", help="the mission to run instead")
    simulate.add_argument("--world", type=Path, metavar="YAML", help="a world file of your own")
    simulate.add_argument(
        "--thesis",
        action="store_true",
        default=None,
        help="agri: the world calibrated to the thesis' 70 runs (docs/sim.md)",
    )
    simulate.add_argument(
        "--library",
        type=Path,
        metavar="DIR",
        help="building blocks (.bpmn) for call activities; they replace the simulator's skills",
    )
    simulate.add_argument("--runs", type=int, metavar="N", help="how many runs (1)")
    simulate.add_argument("--seed", type=int, help="the batch's seed (1)")
    simulate.add_argument("--first", type=int, metavar="N", help="number of the first run (1)")
    simulate.add_argument(
        "--out",
        dest="out_dir",
        metavar="DIR",
        help="where the runs go, a folder or an fsspec URL (runs/<scenario>)",
    )
    simulate.add_argument("--tractors", type=int, metavar="N", help="agri: how many tractors")
    simulate.add_argument(
        "--count",
        dest="counts",
        action="append",
        metavar="GROUP=N",
        help="robots of a group, e.g. tractor=3 (repeatable)",
    )
    simulate.add_argument("--weeds", metavar="N|LOW-HIGH", help="weeds per run, e.g. 2 or 3-6")
    simulate.add_argument(
        "--fault",
        dest="faults",
        action="append",
        metavar="SPEC",
        help="die:ROBOT@T, drop:/TOPIC[,to=ROBOT][,nth=N], battery:ROBOT@T[,rate=R][,for=S]; "
        "@FROM-TO and ,p=P vary it per run (repeatable)",
    )
    simulate.add_argument("--storage", choices=("sqlite3", "mcap"), help="bag storage (sqlite3)")
    simulate.add_argument(
        "--distro",
        choices=("humble", "iron", "jazzy"),
        default=None,
        help="write the bag metadata that this ROS 2 distribution's `ros2 bag` reads (humble, "
        "which every supported distribution reads)",
    )
    simulate.add_argument(
        "--rate", type=float, metavar="HZ", help="odometry and battery samples a second (2)"
    )
    simulate.add_argument("--topics", metavar="A,B", help="also record these robot topics")
    simulate.add_argument("--time-limit", type=float, metavar="SECONDS", help="per run (900)")
    simulate.add_argument(
        "--engine-cost",
        metavar="SPEC",
        help="simulated time the engines' work takes: script=S,condition=S,step=S (seconds), "
        "measured=FACTOR (wall time times FACTOR) or 0 (the world's engine_cost, else 0)",
    )
    simulate.add_argument(
        "--workers", type=int, metavar="N", help="worker processes (one per CPU); 0: none"
    )
    _add_executor(simulate)
    simulate.add_argument(
        "--gui", action="store_true", default=None, help="watch in pybullet's window"
    )
    simulate.add_argument(
        "--pace", type=float, metavar="X", help="simulated seconds per wall second (--gui: 1)"
    )
    simulate.add_argument(
        "--overwrite", action="store_true", default=None, help="replace runs already in --out"
    )
    simulate.add_argument("--quiet", action="store_true", default=None, help="no progress bar")
    simulate.add_argument(
        "--live",
        action="store_true",
        default=None,
        help="watch each run as it goes, as robotale monitor watches robots: tags printed and "
        "stored in Neo4j, alerts, the Mission page following it (--pace, default 1)",
    )
    simulate.add_argument(
        "--log",
        metavar="NAME",
        help="--live: the live log's name (several runs: NAME_run_0001 ...; default "
        "SCENARIO_run_0001 ...)",
    )
    _add_alert_limits(simulate)
    simulate.add_argument(
        "--dashboard",
        metavar="URL",
        help="--live: the dashboard whose Mission page follows the run (http://127.0.0.1:5000)",
    )
    _handled_by(simulate, "simulate.simulate_command")


def _add_log_source(parser: argparse.ArgumentParser, stored: bool = False) -> None:
    """The event log a discovery or perspectives command reads."""
    parser.add_argument("log", nargs="?", type=Path, help="event log file (.csv or .xes)")
    if stored:
        parser.add_argument("--log", dest="log_name", metavar="NAME", help="a log stored in Neo4j")
    _add_mapping(parser)
    _add_case_options(parser)


def _add_case_options(parser: argparse.ArgumentParser) -> None:
    """How a log file's events fall into cases."""
    parser.add_argument(
        "--case-column", metavar="COLUMN", help="the column telling runs apart (default: case)"
    )
    _add_case_gap(parser)


def _add_case_gap(parser: argparse.ArgumentParser) -> None:
    parser.add_argument(
        "--case-gap",
        metavar="DURATION",
        help="without a case column, start a new case after every pause this long between "
        "events, e.g. 1h, 90s, 30min",
    )


def _add_inspect(commands: argparse._SubParsersAction) -> None:
    inspect = commands.add_parser(
        "inspect",
        help="how an event log (CSV or XES) is read: columns, cases, robots, dropped rows",
        description="Show how robotale reads an event log before anything is built on it: "
        "which column is the case, the robot and its type, the lifecycle and the pairing key, "
        "which cells are missing, how many rows were kept or dropped and why, and warnings.",
    )
    inspect.add_argument("log", type=Path, help="event log file (.csv or .xes)")
    _add_mapping(inspect)
    _add_case_options(inspect)
    _handled_by(inspect, "inspect.inspect_command")


def _add_aggregate(commands: argparse._SubParsersAction) -> None:
    aggregate = commands.add_parser(
        "aggregate",
        help="collapse a stored log's events or entities into aggregates, step by step",
        description="Run an aggregation specification (YAML: steps with aggr_type, ent_type, "
        "group_by, where, attr_aggrs, as OCEAN's) on a log stored in Neo4j. Each step "
        "collapses the matching events or entities into Aggregate nodes that keep their CORR, "
        "DF and COMM edges, counted; steps stack and are undone as units. See docs/aggregate.md.",
    )
    aggregate.add_argument("log_name", metavar="LOG", help="the stored log")
    aggregate.add_argument("--spec", type=Path, metavar="FILE", help="the specification to run")
    aggregate.add_argument(
        "--undo",
        dest="undo_step",
        nargs="?",
        const="last",
        metavar="STEP",
        help="undo step STEP and the steps stacked on it (default: the last step)",
    )
    aggregate.add_argument(
        "--steps", action="store_true", default=None, help="list the log's aggregation steps"
    )
    aggregate.add_argument(
        "--json",
        dest="as_json",
        action="store_true",
        default=None,
        help="print each step's initial_events, final_events, initial_entities and "
        "final_entities as JSON",
    )
    _handled_by(aggregate, "aggregate.aggregate_command")


def _add_discover(commands: argparse._SubParsersAction) -> None:
    discover = commands.add_parser(
        "discover",
        help="process models from a log: DFG, aggregated EKG, conformance to a BPMN model",
        description="Discover process models from an event log (thesis 7.1.2).",
    )
    actions = discover.add_subparsers(dest="_action", metavar="ACTION", required=True)

    dfg = actions.add_parser("dfg", help="directly-follows graph (pm4py)")
    _add_log_source(dfg, stored=True)
    _add_log_filters(dfg)
    _add_graph_output(dfg)
    _handled_by(dfg, "discover.dfg_command")

    bpmn = actions.add_parser(
        "bpmn", help="the robots' collaboration as a BPMN model: pools, signals, event handlers"
    )
    _add_log_source(bpmn, stored=True)
    _add_log_filters(bpmn)
    bpmn.add_argument("--out", type=Path, required=True, metavar="BPMN", help="the file to write")
    bpmn.add_argument(
        "--noise",
        type=float,
        metavar="SHARE",
        help="the inductive miner's noise threshold, 0-1 (default 0: every trace fits)",
    )
    bpmn.add_argument(
        "--bind",
        dest="bind_to",
        type=Path,
        metavar="DRIVING.bpmn",
        help="copy each activity's skill and inputs, script or timer, and each signal's type, "
        "payload and data from the same-named element of this model, to run the result",
    )
    _handled_by(bpmn, "discover.bpmn_command")

    ekg = actions.add_parser("ekg", help="aggregated event knowledge graph from Neo4j")
    ekg.add_argument("--log", dest="log_name", required=True, metavar="NAME", help="stored log")
    ekg.add_argument(
        "--aggregate",
        metavar="KEYS",
        help="event properties a class is made of (default: activity,robot)",
    )
    ekg.add_argument(
        "--entities", metavar="TYPES", help="entity types whose DF_C edges to show (default: all)"
    )
    _add_graph_output(ekg)
    _handled_by(ekg, "discover.ekg_command")

    conformance = actions.add_parser(
        "conformance", help="replay each robot against its pool of a BPMN collaboration"
    )
    _add_log_source(conformance)
    conformance.add_argument("--model", required=True, type=Path, help="the .bpmn collaboration")
    conformance.add_argument("--library", type=Path, metavar="DIR", help="building blocks")
    conformance.add_argument(
        "--json", dest="json_out", type=Path, metavar="FILE", help="also write the report as JSON"
    )
    _handled_by(conformance, "discover.conformance_command")

    diff = actions.add_parser(
        "diff",
        help="the driving model against the discovered one: what the robots never used, "
        "what they did beyond it, signals never caught",
    )
    diff.add_argument("driving", type=Path, help="the .bpmn collaboration that drove the robots")
    diff.add_argument("discovered", type=Path, help="the .bpmn discovered from their runs")
    diff.add_argument(
        "--json", dest="json_out", type=Path, metavar="FILE", help="also write it as JSON"
    )
    diff.add_argument(
        "--out",
        type=Path,
        metavar="BPMN",
        help="write the driving model with what was never used drawn red",
    )
    _handled_by(diff, "discover.diff_command")


def _add_log_filters(parser: argparse.ArgumentParser) -> None:
    """The filters of ``discover dfg`` and ``discover bpmn``."""
    for flag, dest, text in (
        ("--case", "cases", "keep these cases (runs)"),
        ("--robot", "robots", "keep these robots"),
        ("--robot-type", "robot_types", "keep these robot types (pools)"),
        ("--activity", "activities", "keep these activities"),
    ):
        parser.add_argument(
            flag, dest=dest, action="append", metavar="A,B", help=f"{text}. Repeatable"
        )
    parser.add_argument("--since", metavar="TIME", help="keep events at or after this ISO time")
    parser.add_argument("--until", metavar="TIME", help="keep events at or before this ISO time")


def _add_graph_output(parser: argparse.ArgumentParser) -> None:
    parser.add_argument(
        "--out", type=Path, metavar="JSON", help="write the graph as JSON (default: print it)"
    )
    parser.add_argument("--svg", type=Path, metavar="SVG", help="draw the graph (needs dot)")
    parser.add_argument(
        "--labels",
        choices=("frequency", "performance"),
        help="what the SVG's edges show (default: frequency)",
    )


def _add_perspectives(commands: argparse._SubParsersAction) -> None:
    perspectives = commands.add_parser(
        "perspectives",
        help="spatial, communication, battery, performance perspectives and bottlenecks",
        description="Enhance the process with the log's perspectives (thesis 6.2.2, 7.2.2): "
        "an HTML report (works offline) and/or JSON.",
    )
    _add_log_source(perspectives, stored=True)
    perspectives.add_argument("--out", type=Path, metavar="HTML", help="write the report as HTML")
    perspectives.add_argument(
        "--json", dest="json_out", type=Path, metavar="JSON", help="write the report as JSON"
    )
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
        metavar="PERCENT",
        help=f"battery level counted as low (default: {LOW_BATTERY_PERCENT:g})",
    )
    _add_delay(perspectives)
    perspectives.add_argument(
        "--only",
        action="append",
        metavar="NAME",
        choices=_Registered("robotale.enhancement.registry.names"),
        help="only this perspective (spatial, communication ...); repeatable (default: all)",
    )
    _handled_by(perspectives, "perspectives.perspectives_command")


def _add_delay(parser: argparse.ArgumentParser) -> None:
    parser.add_argument(
        "--delay",
        type=float,
        metavar="SECONDS",
        help="a message is delayed when its latency is above this (default: when it is in "
        "the slow mode of its channel's two-mode latency distribution; none when its "
        "latencies are all alike)",
    )


def _add_report(commands: argparse._SubParsersAction) -> None:
    report = commands.add_parser(
        "report",
        help="what happened and why: sequence, delays, robots, battery, messages",
        description="Answer an analyst's five questions about a log (its typical sequence "
        "and variants, the bottlenecks, where each robot worked, whether battery mattered, "
        "which messages were delayed, lost or resent) in plain sentences; also as HTML with "
        "the runs' timelines (works offline) and/or JSON.",
    )
    _add_log_source(report, stored=True)
    report.add_argument("--out", type=Path, metavar="HTML", help="write the report as HTML")
    report.add_argument(
        "--json", dest="json_out", type=Path, metavar="JSON", help="write the report as JSON"
    )
    report.add_argument(
        "--threshold",
        type=float,
        metavar="PERCENT",
        help=f"battery level counted as low (default: {LOW_BATTERY_PERCENT:g})",
    )
    _add_delay(report)
    _handled_by(report, "report.report_command")


def _add_compare(commands: argparse._SubParsersAction) -> None:
    compare = commands.add_parser(
        "compare",
        help="what changed between two batches of runs: durations, frequencies, variants, "
        "bottlenecks, messages, battery",
        description="Compare two batches of runs (A, the reference, and B): plain sentences "
        "of what changed, largest and surest first, each difference tested run against run "
        "(Mann-Whitney U and Welch's t, Benjamini-Hochberg adjusted), then the table of "
        "changes.",
    )
    for name, which in (("log_a", "A, the reference"), ("log_b", "B")):
        compare.add_argument(
            name,
            metavar=name.upper(),
            help=f"batch {which}: an event log file (.csv or .xes), or the name of a log "
            "stored in Neo4j when no such file exists",
        )
    _add_mapping(compare)
    _add_case_options(compare)
    compare.add_argument(
        "--json", dest="json_out", type=Path, metavar="JSON", help="also write it as JSON"
    )
    compare.add_argument(
        "--top", type=int, metavar="N", help="how many changes the table lists (default 20)"
    )
    _handled_by(compare, "compare.compare_command")


def main(argv: Sequence[str] | None = None) -> int:
    args = build_parser().parse_args(argv)
    try:
        return run_handler(args)
    except RobotaleError as error:
        print(f"robotale: {error}", file=sys.stderr)
        return 1
    except KeyboardInterrupt:
        print("robotale: interrupted", file=sys.stderr)
        return 130
