"""``msdlab validate``: how strong are the checks? Solutions, templates and mutants, per check.

For instructors, before a release: the checks of each task (hidden ones included) run on
the reference solution (all must pass), on the template (all must fail) and on mutants of
the solution's code (operators, operands, constants, comparisons, dropped terms, signs).
Trivial answers (the solution answering zeros, its input, constants, NaN, inf, empty or
complex arrays) must fail every check. The report gives, per task, how many mutants each
check kills and which it alone kills, the surviving mutants (equivalent to the solution,
with the reason from solutions/equivalent_mutants.json, or a mistake no check catches: a
new check is due) and the kill rate of the mutants not equivalent. Exit status 1 if a
solution fails a check, or a template or a trivial answer passes one.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from ...course import PROJECT_ROOT, TASKS
from ..validate import broken, format_report, validate


def register(subparsers: argparse._SubParsersAction) -> None:
    parser = subparsers.add_parser(
        "validate",
        help="run the checks on solutions, templates and mutants of the solutions (instructors)",
        description=__doc__,
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    parser.add_argument("tasks", nargs="*", type=int, metavar="TASK", help="tasks (default: all)")
    parser.add_argument(
        "--course",
        type=Path,
        default=PROJECT_ROOT,
        help="folder holding solutions/, assignments/ and tests/tasks/ (default: %(default)s)",
    )
    parser.add_argument(
        "--sample", type=int, default=None, help="at most this many random mutants per task"
    )
    parser.add_argument("--seed", type=int, default=0, help="seed of --sample (%(default)s)")
    parser.add_argument(
        "--seconds", type=float, default=30.0, help="time limit per check (%(default)s s)"
    )
    parser.add_argument(
        "--verbose", action="store_true", help="list the checks that kill each mutant"
    )
    parser.set_defaults(run=run)


def run(args: argparse.Namespace) -> int:
    wrong = [task for task in args.tasks if task not in TASKS]
    if wrong:
        raise ValueError(f"no task {wrong[0]}: the tasks are {', '.join(map(str, TASKS))}")
    if args.sample is not None and args.sample < 0:
        raise ValueError(f"--sample must be >= 0, got {args.sample}")
    reports = []
    for task in args.tasks or TASKS:  # each task's report as soon as it is done
        (report,) = validate(
            args.course,
            [task],
            sample=args.sample,
            seed=args.seed,
            seconds=args.seconds,
            progress=lambda line: print(line, file=sys.stderr),
        )
        reports.append(report)
        print(format_report([report], verbose=args.verbose), flush=True)
    if len(reports) > 1:
        print(format_report(reports).splitlines()[-1])  # all tasks together
    return 1 if any(broken(report) for report in reports) else 0
