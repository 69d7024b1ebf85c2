"""``msdlab templates``: make the student templates (assignments/) from the solutions.

For instructors: each '### BEGIN SOLUTION' ... '### END SOLUTION' block of a
solution file becomes 'raise NotImplementedError("Task N: <its TODO>")'.
"""

from __future__ import annotations

import argparse
from pathlib import Path

from ...course import PROJECT_ROOT
from ..templates import differences, generate


def register(subparsers: argparse._SubParsersAction) -> None:
    parser = subparsers.add_parser(
        "templates",
        help="generate the task templates from the reference solutions (instructors)",
        description=__doc__,
    )
    parser.add_argument(
        "--solutions",
        type=Path,
        default=PROJECT_ROOT / "solutions",
        help="folder of the solution files task1.py ... (default: %(default)s)",
    )
    parser.add_argument(
        "--out",
        type=Path,
        default=PROJECT_ROOT / "assignments",
        help="folder the templates are written to (default: %(default)s)",
    )
    parser.add_argument(
        "--check",
        action="store_true",
        help="write nothing; exit 1 if a template is missing or not what the generator makes",
    )
    parser.set_defaults(run=run)


def run(args: argparse.Namespace) -> int:
    if args.check:
        found = differences(args.solutions, args.out)
        for difference in found:
            print(f"stale template: {difference}")
        if found:
            print("run 'msdlab templates' to regenerate them")
            return 1
        print(f"templates in {args.out} are up to date with {args.solutions}")
        return 0
    for path in generate(args.solutions, args.out):
        print(f"wrote {path}")
    return 0
