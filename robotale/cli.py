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
    _add_neo4j(commands)
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
        help="die:ROBOT@T, drop:/TOPIC[,to=ROBOT][,nth=N], battery:ROBOT@T[,rate=R]; "
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
