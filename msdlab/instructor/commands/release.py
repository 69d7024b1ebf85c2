"""``msdlab release OUTDIR``: build the student bundle.

It holds the engine, the task templates (assignments/), the notebooks without
their outputs and the public checks; no solutions/, no hidden checks, and no
line of a solution anywhere (the build stops if one turns up). The bundle has
its own README whose quick start installs it, runs the demo and the checks.
Where the course gives each student their own numbers ("own_numbers": true in its
course.json), each release is one student's: --student ID.
"""

from __future__ import annotations

import argparse
from pathlib import Path

from ...course import PROJECT_ROOT
from .. import release


def register(subparsers: argparse._SubParsersAction) -> None:
    parser = subparsers.add_parser(
        "release", help="build the student bundle (instructors)", description=__doc__
    )
    parser.add_argument("out", type=Path, metavar="OUTDIR", help="folder to create")
    parser.add_argument("--force", action="store_true", help="replace OUTDIR if it is not empty")
    parser.add_argument(
        "--course",
        type=Path,
        default=PROJECT_ROOT,
        help="course folder with solutions/ (default: this installation's, %(default)s)",
    )
    parser.add_argument(
        "--student",
        metavar="ID",
        default=None,
        help="the student (roster id) this release is for, where the course gives each "
        "student their own numbers (course.json)",
    )
    parser.set_defaults(run=run)


def run(args: argparse.Namespace) -> int:
    if not (args.course / "solutions").is_dir():
        raise FileNotFoundError(f"{args.course} has no solutions/: give the course folder")
    files = release.build(args.out, args.course, force=args.force, student=args.student)
    print(f"student release: {len(files)} files in {args.out.resolve()}")
    print("no solutions, no hidden checks, no solution text; notebooks without outputs")
    if args.student is not None:
        print(f"with the own numbers of student {args.student}")
    return 0
