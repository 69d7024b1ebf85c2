"""``msdlab check [TASK]``: run the checks of one task (or all) on your task files and score them.

The checks (tests/tasks) run in a fresh pytest process on a folder laid out
like assignments/ (default: ./assignments, else the course's assignments/). The
table shows each check, its points, pass or fail and what the check saw;
the exit status is 0 only if every check passed.
"""

from __future__ import annotations

import argparse
import shutil
from pathlib import Path

from ..course import TASKS
from ..course.runner import (
    CHECKS,
    ChecksDidNotRun,
    checks_folder,
    implementation_folder,
    run_checks,
)


def register(subparsers: argparse._SubParsersAction) -> None:
    parser = subparsers.add_parser(
        "check",
        help="run the checks of a task on your task files and show the points",
        description=__doc__,
    )
    parser.add_argument(
        "task", nargs="?", default=None, help="task number 1-5 (default: all tasks)"
    )
    parser.add_argument(
        "--impl",
        default=None,
        help="folder with your task1.py ... task5.py, or 'assignments' / 'solutions' "
        "(default: ./assignments if it exists, else the course's assignments/)",
    )
    parser.add_argument(
        "--checks",
        type=Path,
        default=None,
        help=f"folder of the checks (default: {CHECKS} of the course folder you are in, else "
        "of the msdlab installation)",
    )
    parser.add_argument(
        "--hidden", action="store_true", help="also run the instructor-only (hidden) checks"
    )
    parser.add_argument("--report", type=Path, default=None, help="also save the JSON report here")
    parser.add_argument(
        "--timeout", type=float, default=900.0, help="give up after this many seconds (%(default)s)"
    )
    parser.add_argument("-v", "--verbose", action="store_true", help="show pytest's own output too")
    parser.set_defaults(run=run)


def run(args: argparse.Namespace) -> int:
    task = parse_task(args.task)
    checks = checks_folder(args.checks, Path.cwd())
    folder = implementation_folder(args.impl, Path.cwd())
    scope = f"task {task}" if task else "all tasks"
    print(f"msdlab check: {scope} on {folder}")
    try:
        report, output = run_checks(
            checks,
            folder,
            task,
            hidden=args.hidden,
            verbose=args.verbose,
            timeout=args.timeout,
            save=args.report,
        )
    except ChecksDidNotRun as error:
        print(error.output)
        print(error)
        return 2
    if args.verbose:
        print(output)
    width = shutil.get_terminal_size((100, 24)).columns
    print()
    print(report.table(width))
    details = report.details(width)
    if details:
        print("\nwhat the failing checks saw:\n")
        print(details)
    return 0 if report.all_passed else 1


def parse_task(text: str | None) -> int | None:
    """'3' or 'task3' -> 3; None -> None (all tasks)."""
    if text is None:
        return None
    digits = text.lower().removeprefix("task")
    if not digits.isdigit() or int(digits) not in TASKS:
        raise ValueError(f"TASK must be one of {', '.join(map(str, TASKS))}, got {text!r}")
    return int(digits)
