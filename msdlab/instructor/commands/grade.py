"""``msdlab grade SUBMISSION... --out grades.csv``: grade a class's submissions.

Each SUBMISSION is a folder laid out like assignments/. Every submission is
graded in its own workspace by a fresh process running the instructor's checks
(hidden ones included); the submission's code runs in a sandbox and can only
answer with data, under a time and memory limit. Every submission gets a CSV
row (submission, task1 ... task5, total, notes) and, with --feedback, a
feedback file. Exit status 0 if every submission was graded, 1 otherwise.
With --cluster the submissions are graded by Dask workers (msdlab[cluster]).
"""

from __future__ import annotations

import argparse
import os
import sys
import time
from pathlib import Path

from ...analysis.cluster import connect
from ...course import PROJECT_ROOT
from .. import grading
from ..cluster_grading import grade_all_on_cluster


def register(subparsers: argparse._SubParsersAction) -> None:
    parser = subparsers.add_parser(
        "grade",
        help="grade folders of submissions into a CSV (instructors)",
        description=__doc__,
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    parser.add_argument("submissions", nargs="+", type=Path, metavar="SUBMISSION")
    parser.add_argument("--out", type=Path, required=True, help="CSV file to write")
    parser.add_argument("--feedback", type=Path, default=None, help="folder for feedback files")
    parser.add_argument(
        "--jobs", type=int, default=os.cpu_count() or 1, help="submissions at once (%(default)s)"
    )
    parser.add_argument(
        "--timeout", type=float, default=600.0, help="seconds per submission (%(default)s)"
    )
    parser.add_argument(
        "--call-timeout", type=float, default=60.0, help="seconds per call into it (%(default)s)"
    )
    parser.add_argument(
        "--memory", type=int, default=2048, help="memory limit per submission, MB (%(default)s)"
    )
    parser.add_argument(
        "--checks",
        type=Path,
        default=PROJECT_ROOT / "tests" / "tasks",
        help="folder of the checks, hidden ones included (default: the course's tests/tasks)",
    )
    parser.add_argument(
        "--cluster",
        metavar="ADDRESS|local:N",
        help="grade on a Dask scheduler, or on N local worker processes (instead of --jobs)",
    )
    parser.set_defaults(run=run)


def run(args: argparse.Namespace) -> int:
    if not (args.checks / "conftest.py").is_file() and not list(args.checks.glob("test_*.py")):
        raise FileNotFoundError(f"no checks in {args.checks}; give --checks DIR")
    if args.jobs < 1 or args.timeout <= 0 or args.call_timeout <= 0 or args.memory < 256:
        raise ValueError("--jobs >= 1, --timeout and --call-timeout > 0 and --memory >= 256 MB")
    submissions = grading.find_submissions(args.submissions)
    width = max(len(s.name) for s in submissions)
    where = f"on the cluster {args.cluster}" if args.cluster else f"{args.jobs} at a time"
    print(f"grading {len(submissions)} submissions, {where}", file=sys.stderr)

    def progress(grade: grading.Grade, done: int, count: int) -> None:
        if grade.graded:
            result = f"{grade.total}/{grade.report.points} points"
        else:
            result = "NOT GRADED: " + "; ".join(grade.notes)
        print(f"[{done:>{len(str(count))}}/{count}] {grade.submission:<{width}}  {result}  "
              f"({grade.seconds:.1f} s)", file=sys.stderr)  # fmt: skip

    started = time.monotonic()
    limits = dict(timeout=args.timeout, call_timeout=args.call_timeout, memory_mb=args.memory)
    if args.cluster:
        with connect(args.cluster) as client:
            grades = grade_all_on_cluster(
                submissions, args.checks.resolve(), client, progress=progress, **limits
            )
    else:
        grades = grading.grade_all(
            submissions, args.checks.resolve(), jobs=args.jobs, progress=progress, **limits
        )
    grading.write_csv(grades, args.out)
    if args.feedback is not None:
        args.feedback.mkdir(parents=True, exist_ok=True)
        for grade in grades:
            (args.feedback / f"{grade.submission}.md").write_text(grading.feedback(grade))
    print(grading.summary(grades, time.monotonic() - started))
    print(f"grades written to {args.out}")
    return 0 if all(grade.graded for grade in grades) else 1
