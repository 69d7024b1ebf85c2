"""The ``msdlab`` command line: one sub-command per module in `msdlab.commands`."""

from __future__ import annotations

import argparse
import os
import sys
from collections.abc import Sequence

from .commands import COMMANDS


def build_parser() -> argparse.ArgumentParser:
    """The argument parser with every sub-command registered."""
    parser = argparse.ArgumentParser(
        prog="msdlab", description="Mass-spring-damper simulation for teaching."
    )
    subparsers = parser.add_subparsers(dest="command", metavar="COMMAND")
    for command in COMMANDS:
        command.register(subparsers)
    return parser


def configure_process() -> None:
    """Process-wide settings, made by the command line, never by importing msdlab.

    Waiting threads sleep instead of spinning (``OMP_WAIT_POLICY=PASSIVE``): a
    spinning thread keeps waiting work off a shared core (a 0.5 ms step took 30 ms).
    A value the user set is kept.
    """
    os.environ.setdefault("OMP_WAIT_POLICY", "PASSIVE")


def main(argv: Sequence[str] | None = None) -> int:
    """Run ``msdlab`` with ``argv`` (default: the process arguments); return the exit status."""
    configure_process()
    parser = build_parser()
    args = parser.parse_args(argv)
    if args.command is None:
        parser.print_help()
        return 2
    try:
        return int(args.run(args) or 0)
    except (ValueError, TypeError, OSError, RuntimeError) as error:
        print(f"msdlab {args.command}: error: {error}", file=sys.stderr)
        return 2
