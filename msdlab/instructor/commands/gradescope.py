"""``msdlab gradescope OUT.zip``: build a Gradescope autograder for the course.

Upload OUT.zip as the assignment's autograder. Gradescope runs setup.sh once
(msdlab from the zip, the checks' dependencies from the package index), then
run_autograder for every submission: the student's task1.py ... task5.py, at
the top level or in assignments/, are graded with the instructor's checks,
hidden ones included, as by `msdlab grade`, and the score, each check and the
per-task totals go back to Gradescope. Hidden checks are shown to students
after the grades are published (or never, with --hidden-visibility hidden).
The container Gradescope starts for each submission is the isolation
boundary; the sandbox inside it runs at --isolation (default: process).
Where the course gives each student their own numbers (its course.json), the zip
carries that setting and grades each student against the numbers of their
roster id, taken from Gradescope's roster (--roster-id: the student id, sid, or
the email). The zip is written outside the course folder, as a release is.
"""

from __future__ import annotations

import argparse
from pathlib import Path

from ...course import PROJECT_ROOT, own_numbers
from ..judging.gradescope import HIDDEN_VISIBILITIES, ROSTER_IDS, Settings, build


def register(subparsers: argparse._SubParsersAction) -> None:
    parser = subparsers.add_parser(
        "gradescope",
        help="build a Gradescope autograder zip (instructors)",
        description=__doc__,
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    parser.add_argument("out", type=Path, metavar="OUT.zip", help="the autograder zip to write")
    parser.add_argument(
        "--checks",
        type=Path,
        default=PROJECT_ROOT / "tests" / "tasks",
        help="folder of the checks, hidden ones included (default: the course's tests/tasks)",
    )
    parser.add_argument(
        "--hidden-visibility",
        choices=HIDDEN_VISIBILITIES,
        default="after_published",
        help="when students see the hidden checks' results (default: %(default)s)",
    )
    parser.add_argument(
        "--isolation",
        default="process",
        help="the sandbox's isolation level inside Gradescope's container (default: %(default)s)",
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
        "--roster-id",
        choices=ROSTER_IDS,
        default="sid",
        help="with own numbers: the field of Gradescope's roster that holds the id each "
        "student's release was built with (default: %(default)s, the student id)",
    )
    parser.set_defaults(run=run)


def run(args: argparse.Namespace) -> int:
    settings = Settings(
        hidden_visibility=args.hidden_visibility,
        isolation=args.isolation,
        timeout=args.timeout,
        call_timeout=args.call_timeout,
        memory_mb=args.memory,
        roster_id=args.roster_id,
    )
    out, course = args.out.resolve(), own_numbers.course_of(args.checks)
    for folder in (PROJECT_ROOT, course):
        if folder in out.parents and (folder / "solutions").is_dir():
            raise ValueError(
                f"write the autograder outside the course folder {folder}, e.g. "
                f"{folder.parent / args.out.name}"
            )
    names = build(args.out, PROJECT_ROOT, args.checks, settings)
    checks = sum(1 for name in names if name.startswith("checks/test_"))
    print(f"Gradescope autograder: {len(names)} files ({checks} check files) in {args.out}")
    print("upload it as the assignment's autograder (Configure Autograder > Zip file upload)")
    if own_numbers.SETTINGS_FILE in names:
        print(f"with own numbers: each student is graded against the numbers of their "
              f"{args.roster_id} in Gradescope's roster")  # fmt: skip
    return 0
