"""``msdlab check [TASK]``: run the checks of one task (or all) on your task files and score them.

The checks (tests/tasks) run in a fresh pytest process on a folder laid out
like assignments/ (default: ./assignments, else the course's assignments/). The
table shows each check, its points, pass or fail and what the check saw;
the exit status is 0 only if every check passed.
"""

from __future__ import annotations

import argparse
import os
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

from ..course import PROJECT_ROOT, TASKS, loader
from ..course.report import CheckReport

CHECKS = Path("tests") / "tasks"


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
    with tempfile.TemporaryDirectory(prefix="msdlab-check-") as scratch:
        report_path = Path(scratch) / "report.json"
        command = pytest_command(checks, folder, task, args.hidden, report_path, args.verbose)
        try:
            process = subprocess.run(
                command,
                cwd=checks,
                env={**os.environ, "PYTHONDONTWRITEBYTECODE": "1"},
                capture_output=True,
                text=True,
                timeout=args.timeout,
            )
        except subprocess.TimeoutExpired:
            print(f"the checks did not finish within {args.timeout:g} s: is there an endless loop?")
            return 2
        if args.verbose or process.returncode not in (0, 1) or not report_path.exists():
            print(process.stdout + process.stderr)
        if not report_path.exists() or process.returncode not in (0, 1):
            print(f"the checks could not run (pytest exit status {process.returncode})")
            return 2
        report = CheckReport.read(report_path)
        if args.report:
            shutil.copyfile(report_path, args.report)
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


def checks_folder(given: Path | None, cwd: Path) -> Path:
    """The folder of the checks: given, else the course's tests/tasks (yours first)."""
    if given is None:
        local = loader.course_root(cwd) / CHECKS
        given = local if local.is_dir() else PROJECT_ROOT / CHECKS
    folder = Path(given).expanduser().resolve()
    if not folder.is_dir():
        raise FileNotFoundError(f"no checks folder at {folder}")
    return folder


def implementation_folder(spec: str | None, cwd: Path) -> Path:
    """The folder of task files to check; a student's ./assignments comes first."""
    if spec is None:
        local = loader.course_root(cwd) / "assignments"
        folder = local if local.is_dir() else PROJECT_ROOT / "assignments"
    elif spec in loader.NAMED:
        local = loader.course_root(cwd) / spec
        folder = local if local.is_dir() else PROJECT_ROOT / spec
    else:
        folder = Path(spec).expanduser()
    folder = folder.resolve()
    if not folder.is_dir():
        raise FileNotFoundError(f"no folder of task files at {folder}")
    return folder


def pytest_command(
    checks: Path, folder: Path, task: int | None, hidden: bool, report: Path, verbose: bool
) -> list[str]:
    """The pytest command line that runs the chosen checks on ``folder``."""
    selected = f"task{task}" if task else " or ".join(f"task{n}" for n in TASKS)
    marker = selected if hidden else f"({selected}) and not hidden"
    return [
        sys.executable,
        "-m",
        "pytest",
        str(checks),
        f"--impl={folder}",
        f"--msdlab-report={report}",
        "-m",
        marker,
        "-p",
        "no:cacheprovider",
        "-p",
        "no:nbval",  # not needed by the checks; loading it takes most of a second
        "--tb=short" if verbose else "--tb=no",
        "-q",
    ]
