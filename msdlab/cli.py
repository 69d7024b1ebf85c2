"""The ``msdlab`` command line: one sub-command per module in `msdlab.commands`."""

from __future__ import annotations

import argparse
import sys
from collections.abc import Sequence

from .commands import COMMANDS, command_module
from .engine.backends.process import configure_process


def build_parser(commands: Sequence[str] = COMMANDS) -> argparse.ArgumentParser:
    """The argument parser with these sub-commands registered (default: every one)."""
    parser = argparse.ArgumentParser(
        prog="msdlab", description="Mass-spring-damper simulation for teaching."
    )
    subparsers = parser.add_subparsers(dest="command", metavar="COMMAND")
    for name in commands:
        command_module(name).register(subparsers)
    return parser


def main(argv: Sequence[str] | None = None) -> int:
    """Run ``msdlab`` with ``argv`` (default: the process arguments); return the exit status."""
    configure_process()
    argv = sys.argv[1:] if argv is None else list(argv)
    parser = build_parser(named_command(argv))
    args = parser.parse_args(argv)
    if args.command is None:
        parser.print_help()
        return 2
    try:
        return int(args.run(args) or 0)
    except (ValueError, TypeError, OSError, RuntimeError) as error:
        print(f"msdlab {args.command}: error: {error}", file=sys.stderr)
        return 2


def named_command(argv: Sequence[str]) -> Sequence[str]:
    """The command ``argv`` starts with, alone (``msdlab check 2`` imports only what
    ``check`` needs); every command for anything else (``msdlab --help``, a typo)."""
    return argv[:1] if argv[:1] and argv[0] in COMMANDS else COMMANDS
