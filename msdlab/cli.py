"""The ``msdlab`` command line: one sub-command per module in `msdlab.commands`."""

from __future__ import annotations

import argparse
import sys
from collections.abc import Sequence

from .commands import COMMANDS
from .process import configure_process


def build_parser() -> argparse.ArgumentParser:
    """The argument parser with every sub-command registered."""
    parser = argparse.ArgumentParser(
        prog="msdlab", description="Mass-spring-damper simulation for teaching."
    )
    subparsers = parser.add_subparsers(dest="command", metavar="COMMAND")
    for command in COMMANDS:
        command.register(subparsers)
    return parser


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
