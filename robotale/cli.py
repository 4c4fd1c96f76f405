"""The ``robotale`` command.

Thin by design: each ``_add_*`` function declares one command group's arguments and its handler
imports the part that does the work only when the command runs, so ``robotale --help`` stays
fast. A :class:`~robotale.errors.RobotaleError` ends the command with its one-sentence message
and exit status 1.
"""

from __future__ import annotations

import argparse
import sys
from collections.abc import Sequence

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
    return parser


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
