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
