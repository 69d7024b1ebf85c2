"""``msdlab check [TASK]``: run the checks of one task (or all) on your task files and score them.

The checks (tests/tasks) run in a fresh pytest process on a folder laid out
like assignments/ (default: your assignments/; the reference answers only when
asked: --impl solutions or MSDLAB_IMPL=solutions); each
call into your files may take --call-timeout seconds. The table shows each
check, its points, pass or fail and what the check saw (a long message once,
below it); the last line says what the hidden checks, which run only when your
work is graded, are worth. The exit status is 0 only if every check passed.
While they run, a line says which check is running. Each function of your task
files may take --task-timeout seconds of processor time in its task's checks, as
when graded: code stopped by either limit is named by its file, line and function.
"""

from __future__ import annotations

import argparse
import shutil
import sys
import tempfile
import time
from pathlib import Path
from typing import TextIO

from ..course import PROJECT_ROOT, TASKS, manifest, own_numbers
from ..course.loader import ENV_IMPL
from ..course.runner import (
    CALL_TIMEOUT,
    CHECKS,
    TASK_TIMEOUT,
    ChecksDidNotRun,
    checks_folder,
    implementation_folder,
    implementation_spec,
    install_command,
    missing_test_tools,
    run_checks,
)

HIDDEN_FILES = "test_*_hidden.py"


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
        help="folder with your task1.py ... task5.py, or 'assignments' / 'solutions' (default: "
        "$MSDLAB_IMPL, else the assignments/ of the course folder you are in)",
    )
    parser.add_argument(
        "--checks",
        type=Path,
        default=None,
        help=f"folder of the checks (default: {CHECKS} of the course folder you are in, else "
        "of the msdlab installation)",
    )
    parser.add_argument(
        "--hidden",
        action="store_true",
        help="also run the instructor-only (hidden) checks"
        if has_hidden_checks(PROJECT_ROOT / CHECKS)
        else argparse.SUPPRESS,  # a student's release has none to run
    )
    parser.add_argument("--report", type=Path, default=None, help="also save the JSON report here")
    parser.add_argument(
        "--timeout", type=float, default=900.0, help="give up after this many seconds (%(default)s)"
    )
    parser.add_argument(
        "--call-timeout",
        type=float,
        default=CALL_TIMEOUT,
        help="seconds one call into your task files, or a task file's import, may take "
        "(%(default)s)",
    )
    parser.add_argument(
        "--task-timeout",
        type=float,
        default=TASK_TIMEOUT,
        help="processor seconds each function of your task files may take in its task's "
        "checks, all its calls together, as when your work is graded (%(default)s)",
    )
    parser.add_argument("-v", "--verbose", action="store_true", help="show pytest's own output too")
    parser.set_defaults(run=run)


def run(args: argparse.Namespace) -> int:
    task = parse_task(args.task)
    if min(args.timeout, args.call_timeout, args.task_timeout) <= 0:
        raise ValueError(
            "--timeout, --call-timeout and --task-timeout must be positive numbers of seconds"
        )
    missing = missing_test_tools()
    if missing:
        print(f"msdlab check needs {' and '.join(missing)} (the grade extra); install them with:")
        print(f"  {install_command(Path.cwd())}")
        return 2
    checks = checks_folder(args.checks, Path.cwd())
    spec = implementation_spec(args.impl)
    folder = implementation_folder(spec, Path.cwd())
    if args.hidden and not has_hidden_checks(checks):
        print("msdlab check: --hidden has nothing to run here:")
        print("the hidden checks are not in this copy of the course. They run when your work")
        print("is graded; the last line of msdlab check says what they are worth.")
        return 2
    scope = f"task {task}" if task else "all tasks"
    print(f"msdlab check: {scope} on {folder}")
    if spec == "solutions":
        print(f"  (the reference answers, not your task files: asked by --impl or ${ENV_IMPL})")
    own = own_numbers.announced(folder)
    if own is not None:
        print(f"  with {own}")
    progress = ProgressLine(sys.stdout)
    with tempfile.TemporaryDirectory(prefix="msdlab-check-") as scratch:
        points = Path(scratch) / manifest.FILE_NAME
        try:
            report, output = run_checks(
                checks,
                folder,
                task,
                hidden=args.hidden,
                verbose=args.verbose,
                timeout=args.timeout,
                save=args.report,
                call_timeout=args.call_timeout,
                task_timeout=args.task_timeout,
                points=points,
                progress=progress,
            )
        except ChecksDidNotRun as error:
            progress.close()
            print(error.output)
            print(error)
            return 2
        worth = manifest.hidden_worth(checks, points, task)
    progress.close()
    if args.verbose:
        print(output)
    width = shutil.get_terminal_size((100, 24)).columns
    print()
    print(report.printout(width, worth))
    return 0 if report.all_passed else 1


def has_hidden_checks(checks: Path) -> bool:
    """Whether the checks folder holds the instructor-only checks (a release has none)."""
    return any(Path(checks).glob(HIDDEN_FILES))


class ProgressLine:
    """What the checks are doing while they run: on a terminal one line, rewritten as each
    check starts and each second (its name and the seconds it has run); elsewhere (a log) a
    line as each task starts and one for a check still running after `SLOW` seconds."""

    SLOW = 10.0

    def __init__(self, out: TextIO) -> None:
        self.out, self.live = out, out.isatty()
        self.check, self.task, self.since, self.note_at = "", "", time.monotonic(), self.SLOW

    def __call__(self, check: str | None) -> None:
        now = time.monotonic()
        if check is not None:
            self.check, self.since, self.note_at = check, now, self.SLOW
        running = now - self.since
        if self.live:
            text = f"  {self.check} ({running:.0f} s)" if self.check else "  starting"
            self.out.write(f"\r{text[: shutil.get_terminal_size().columns - 1]}\x1b[K")
        elif check is not None and check.split(":")[0] != self.task:
            self.task = check.split(":")[0]
            self.out.write(f"  {self.task}...\n")
        elif self.check and running >= self.note_at:
            self.note_at = running + 30.0
            self.out.write(f"  still running {self.check} ({running:.0f} s)\n")
        self.out.flush()

    def close(self) -> None:
        """Clear the line (on a terminal) before the results are printed."""
        if self.live:
            self.out.write("\r\x1b[K")
            self.out.flush()


def parse_task(text: str | None) -> int | None:
    """'3' or 'task3' -> 3; None -> None (all tasks)."""
    if text is None:
        return None
    digits = text.lower().removeprefix("task")
    if not digits.isdigit() or int(digits) not in TASKS:
        raise ValueError(f"TASK must be one of {', '.join(map(str, TASKS))}, got {text!r}")
    return int(digits)
