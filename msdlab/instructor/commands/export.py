"""``msdlab export GRADES --roster ROSTER --format canvas --out FILE``: the grades for an LMS.

Reads the grades ``msdlab grade`` recorded in the gradebook GRADES.db beside the grades
file GRADES (GRADES may name either; for a course graded before that database, the grades
file itself), final totals with late penalties and manual changes, and a roster whose
first line names its columns (id, name, email, sis_id, ...), and writes the grades in the
form Canvas or Moodle imports, or as a plain CSV with the roster's columns kept. No line
of the file is a summary, except Canvas's own "Points Possible" line.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from ..outputs import export
from ..points import gradebook_db


def register(subparsers: argparse._SubParsersAction) -> None:
    parser = subparsers.add_parser(
        "export",
        help="the grades as a Canvas, Moodle or plain CSV file (instructors)",
        description=__doc__,
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    parser.add_argument(
        "grades", type=Path, metavar="GRADES", help="the grades file msdlab grade --out wrote"
    )
    parser.add_argument(
        "--roster", type=Path, help="CSV with a header: id, name, email, sis_id, ..."
    )
    parser.add_argument("--format", choices=export.FORMATS, default="csv", dest="form")
    parser.add_argument("--out", type=Path, required=True, help="CSV file to write")
    parser.add_argument(
        "--assignment",
        default="msdlab",
        help="the assignment's column name in the LMS (default: %(default)s)",
    )
    parser.set_defaults(run=run)


def run(args: argparse.Namespace) -> int:
    grades = args.grades.with_suffix(".csv") if args.grades.suffix == ".db" else args.grades
    if not grades.is_file() and not gradebook_db.beside(grades).is_file():
        raise FileNotFoundError(
            f"no grades at {grades} nor a gradebook {gradebook_db.beside(grades)}; give the "
            "grades file msdlab grade --out wrote"
        )
    if args.roster is None and args.form != "csv":
        raise ValueError(f"--format {args.form} needs --roster FILE (names and ids for the LMS)")
    roster = export.read_roster(args.roster) if args.roster else None
    lines = export.table(grades, roster, args.form, args.assignment, args.out)
    export.write(lines, args.out)
    students = len(lines) - (2 if args.form == "canvas" else 1)
    print(f"{students} students written to {args.out} ({args.form})", file=sys.stderr)
    return 0
