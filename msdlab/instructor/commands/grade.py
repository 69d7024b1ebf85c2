"""``msdlab grade SUBMISSION... --out grades.csv``: grade a class's submissions.

Each SUBMISSION is a folder laid out like assignments/, a folder holding
assignments/, or a zip file of either; its row's id is its path relative to the
submissions' common parent (class/alice/assignments -> alice), or the id given
by --roster FILE (CSV rows 'id,folder-or-zip'). Every submission is graded in
its own workspace by a fresh process running the instructor's checks (hidden
ones included); the submission's code runs in a sandbox and can only answer
with data, under a time and memory limit. Every submission gets a CSV row (id,
source, task1 ... task5, points, the late work columns, total, notes; per check
with --detail); the first row holds the maximum points. --due, --late-policy
and --extensions charge late work; the changes in GRADES.adjustments.csv beside
the CSV (id,task,change,reason) are applied after every run. Rows of earlier
runs in the CSV are kept, a submission graded again gets its row replaced,
and --resume skips those already graded with the same checks. --feedback DIR
writes DIR/students/ID.md (to hand out), DIR/instructor/ID.md (everything)
and DIR/summary.md (over every row of the CSV). Every run writes the class at a
glance beside the CSV (GRADES.class.html: points per task, each check's failure rate,
the usual causes, a check x student map, hand-in times not verified). Exit status 0 if every
submission was graded, 1 if some could not be (their notes say why), 2 if the
grader itself failed (its sandbox could not start, or an error of its own, named
in the notes: no student feedback file is written for those submissions; fix it
and run again with --resume). With --cluster ADDRESS the submissions are graded
by a Dask scheduler's workers (msdlab[cluster]).
"""

from __future__ import annotations

import argparse
import dataclasses
import os
import sys
import tempfile
import time
from pathlib import Path

from tqdm.auto import tqdm

from ...analysis.cluster import parse_cluster
from ...course import PROJECT_ROOT, TASKS, own_numbers
from .. import (
    class_report,
    copied_numbers,
    feedback,
    final_points,
    gradebook,
    grading,
    intake,
    sandbox,
    term_options,
)
from ..cluster_grading import grade_all_on_cluster
from . import similarity


def register(subparsers: argparse._SubParsersAction) -> None:
    parser = subparsers.add_parser(
        "grade",
        help="grade folders of submissions into a CSV (instructors)",
        description=__doc__,
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    parser.add_argument("submissions", nargs="*", type=Path, metavar="SUBMISSION")
    parser.add_argument(
        "--roster", type=Path, default=None, help="CSV of 'id,folder-or-zip' rows instead"
    )
    parser.add_argument("--out", type=Path, required=True, help="CSV file to write")
    parser.add_argument("--feedback", type=Path, default=None, help="folder for feedback files")
    parser.add_argument("--detail", action="store_true", help="also a column per check")
    parser.add_argument(
        "--similarity",
        action="store_true",
        help="also the similarity report (msdlab similarity) in the folder similarity/ beside "
        "the CSV; it changes no points",
    )
    parser.add_argument(
        "--resume", action="store_true", help="skip submissions graded with the same checks"
    )
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
        "--isolation",
        choices=sandbox.ISOLATION_LEVELS,
        default="namespace",
        help="namespace (default): each submission in its own namespaces (bubblewrap), "
        "seeing only its task files; process: a plain child process, weaker, named in "
        "every row's notes",
    )
    parser.add_argument(
        "--allow-delegation",
        default="",
        metavar="TASKS",
        help="comma-separated tasks (e.g. 2,5) whose checks let submissions call the engine's "
        "answer to them; by default such calls are refused and the row's notes say so",
    )
    parser.add_argument(
        "--cluster",
        metavar="ADDRESS|local:N",
        help="grade on a Dask scheduler's workers, or N at a time here (local:N is --jobs N)",
    )
    term_options.register(parser)
    parser.set_defaults(run=run)


def run(args: argparse.Namespace) -> int:
    if not (args.checks / "conftest.py").is_file() and not list(args.checks.glob("test_*.py")):
        raise FileNotFoundError(f"no checks in {args.checks}; give --checks DIR")
    if args.jobs < 1 or args.timeout <= 0 or args.call_timeout <= 0 or args.memory < 256:
        raise ValueError("--jobs >= 1, --timeout and --call-timeout > 0 and --memory >= 256 MB")
    address, jobs = parse_cluster(args.cluster) if args.cluster else (None, args.jobs)
    problem = sandbox.isolation_problem(args.isolation)
    if problem is not None:
        print(f"msdlab grade: {problem}", file=sys.stderr)
        return 2
    if bool(args.roster) == bool(args.submissions):
        raise ValueError("give SUBMISSION folders or zip files, or --roster FILE (not both)")
    if args.similarity:
        similarity.require_copydetect()
    book = gradebook.Gradebook.load(args.out)
    checks = args.checks.resolve()
    terms = term_options.terms(args)

    def save() -> dict[str, list[str]]:
        """Settle every row's final points (late work, manual changes), then write."""
        explained = final_points.settle(book.rows, terms)
        book.write(args.out)
        return explained

    with (
        intake.from_roster(args.roster)
        if args.roster
        else intake.from_paths(args.submissions) as found,
        tempfile.TemporaryDirectory(prefix="msdlab-intake-") as scratch,
    ):
        entries = {entry.id: entry for entry in found.entries}
        term_options.read_hand_ins(entries, args.handed_in, terms, args.timezone, Path(scratch))
        prints = {  # nothing is read from a submission refused at intake (a link, ...)
            i: gradebook.fingerprint(checks, e.folder)
            for i, e in entries.items()
            if e.problem is None
        }
        todo = [e for e in entries.values() if e.problem is None]
        if args.resume:
            todo = [e for e in todo if book.fingerprint_of(e.id) != prints[e.id]]
        skipped = len(entries) - len(todo) - sum(e.problem is not None for e in entries.values())
        unusable = [grading.Grade(e.id, None, [e.problem]) for e in entries.values() if e.problem]
        for grade in unusable:
            book.record(
                shown(grade, entries[grade.submission]),
                entries[grade.submission],
                None,
                args.detail,
            )
        where = f"on the cluster {address}" if address else f"{jobs} at a time"
        plural = "" if len(todo) == 1 else "s"
        resumed = f" ({skipped} unchanged since graded, skipped)" if skipped else ""
        print(
            f"grading {len(todo)} submission{plural}{resumed}, {where}",
            file=sys.stderr,
        )
        width = max(len(e.id) for e in entries.values())

        def progress(grade: grading.Grade, done: int, count: int) -> None:
            entry = entries[grade.submission]
            book.record(shown(grade, entry), entry, prints[grade.submission], args.detail)
            save()  # after each: an interrupted run keeps what was graded
            if grade.graded:
                result = f"{grade.total}/{grade.report.points} points"
            else:
                result = "NOT GRADED: " + "; ".join(grade.notes)
            tqdm.write(f"[{done:>{len(str(count))}}/{count}] {grade.submission:<{width}}  "
                       f"{result}  ({grade.seconds:.1f} s)", file=sys.stderr)  # fmt: skip

        started = time.monotonic()
        own = own_numbers.enabled(own_numbers.course_of(checks))
        options = dict(
            timeout=args.timeout,
            call_timeout=args.call_timeout,
            memory_mb=args.memory,
            isolation=args.isolation,
            allow_delegation=_tasks(args.allow_delegation),
            own_numbers=own,
        )
        graded = [grading.Submission(e.id, e.folder) for e in todo]
        if not graded:
            grades = []
        elif address is not None:
            grades = grade_all_on_cluster(graded, checks, address, progress=progress, **options)
        else:
            grades = grading.grade_all(graded, checks, jobs=jobs, progress=progress, **options)
        explained = save()
        grades = unusable + grades
        rows = class_report.rows_of(book, grades)
        page = class_report.beside(args.out)
        class_report.write_html(rows, book.maximum, page)
        hints = copied_hints(grades, entries, set(book.rows)) if own else {}
        for student, hint in hints.items():
            print(f"{student}: {hint}", file=sys.stderr)
        if args.feedback is not None:
            section = class_report.summary_section(rows, os.path.relpath(page, args.feedback))
            write_feedback(args.feedback, grades, entries, book, section, hints)
            final_points.refresh_feedback(
                args.feedback, book.rows, explained, book.maximum.get("total", "")
            )
        if args.similarity:
            folders = {i: e.folder for i, e in entries.items() if e.problem is None}
            similarity.write_report(folders, args.out.parent / "similarity")
    term_options.report(terms, set(book.rows), args.out)
    print(grading.summary(grades, time.monotonic() - started))
    if args.isolation != "namespace":
        print(f"isolation: {args.isolation} (weaker than namespace; submissions were not "
              "isolated by the operating system)")  # fmt: skip
    kept = len(book.rows) - len(grades)
    print(
        f"grades written to {args.out}" + (f" ({kept} rows of earlier runs kept)" if kept else "")
    )
    print(f"class report written to {class_report.beside(args.out)}")
    failed = [grade for grade in grades if grade.grader_failed]
    if failed:
        print(grader_failure(failed), file=sys.stderr)
        return 2
    return 0 if all(grade.graded for grade in grades) else 1


def grader_failure(failed: list[grading.Grade]) -> str:
    """What to tell the instructor when the grader itself failed on ``failed``."""
    note = next(n for n in failed[0].notes if n.startswith(grading.GRADER_ERROR))
    plural = "s" if len(failed) > 1 else ""
    return (
        f"msdlab grade: the grader failed on {len(failed)} submission{plural}, no fault of "
        f"their authors, who got no feedback file: {feedback.scrub(note)}. Fix the grader and "
        "run the same command with --resume to grade only those."
    )


def shown(grade: grading.Grade, entry: intake.Entry) -> grading.Grade:
    """``grade`` with the intake's notes on its submission first (for the CSV and feedback)."""
    return dataclasses.replace(grade, notes=[*entry.notes, *grade.notes])


def copied_hints(
    grades: list[grading.Grade], entries: dict[str, intake.Entry], roster: set[str]
) -> dict[str, str]:
    """For the instructor: the submissions whose task 1 constants are not their author's
    own numbers, and whose they are (`copied_numbers`), among ``roster`` and this run's."""
    everyone = roster | set(entries)
    found = {
        grade.submission: copied_numbers.hint(
            grade.submission, entries[grade.submission].folder, everyone
        )
        for grade in grades
        if grade.graded
    }
    return {student: hint for student, hint in found.items() if hint is not None}


def write_feedback(
    folder: Path,
    grades: list[grading.Grade],
    entries: dict[str, intake.Entry],
    book: gradebook.Gradebook,
    class_section: str = "",
    hints: dict[str, str] | None = None,
) -> None:
    """DIR/students/ID.md (none where the grader failed), DIR/instructor/ID.md (with the
    ``hints`` for the instructor only), and DIR/summary.md over every row of ``book``,
    ``class_section`` at its end."""
    hints = hints or {}
    for kind in ("students", "instructor"):
        (folder / kind).mkdir(parents=True, exist_ok=True)
    for grade in (shown(g, entries[g.submission]) for g in grades):
        stem = intake.file_stem(grade.submission)
        student = folder / "students" / f"{stem}.md"
        if grade.grader_failed:  # nothing to hand out; an earlier run's file is out of date
            student.unlink(missing_ok=True)
        else:
            student.write_text(feedback.for_student(grade), encoding="utf-8")
        source = intake.escaped(str(entries[grade.submission].source))
        (folder / "instructor" / f"{stem}.md").write_text(
            feedback.for_instructor(grade, source, hints.get(grade.submission)),
            encoding="utf-8",
        )
    summary = feedback.class_summary(book, grades) + class_section
    (folder / "summary.md").write_text(summary, encoding="utf-8")


def _tasks(text: str) -> list[int]:
    """ "2,5" -> [2, 5]; a clear error for anything but task numbers."""
    parts = [part.strip().removeprefix("task") for part in text.split(",") if part.strip()]
    if not all(part.isdigit() and int(part) in TASKS for part in parts):
        raise ValueError(f"--allow-delegation takes task numbers {TASKS} like 2,5; got {text!r}")
    return [int(part) for part in parts]
