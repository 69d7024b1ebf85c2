"""``msdlab grade SUBMISSION... --out grades.csv``: grade a class's submissions.

Each SUBMISSION is a folder laid out like assignments/, a folder holding
assignments/, a zip file of either, or a git repository (or a folder in one: its
commits are read as data, never by running git); its row's id is its path relative to
the submissions' common parent (class/alice/assignments -> alice), or the id given
by --roster FILE (a first line 'id,folder', then one line per student; a student
whose folder is not there gets a row 'nothing handed in', 0 points). With both, each
SUBMISSION's id must be in the roster. An id that is not a student's (reserved, a
lookalike, unknown) refuses that one submission; the others are graded. Each hand-in
time is marked by who controls it; --unverified-time says what one the student could
set gets. Every submission is graded in
its own workspace by a fresh process running the instructor's checks (hidden
ones included); the submission's code runs in a sandbox and can only answer
with data, under a time and memory limit (--task-timeout: processor seconds per
function of a task, all its calls together). Each result is committed to the gradebook
GRADES.db beside the CSV as soon as it is graded; the CSV (id, source, task1 ...
task5, points, the late work columns, total, notes; per check with --detail; the
first row holds the maximum points), the feedback (--feedback DIR: DIR/students/ID.md
to hand out, DIR/instructor/ID.md with everything, DIR/summary.md) and the class at
a glance (GRADES.class.html) are rendered from it over the whole class at the end of
the run (or at its interrupt); --render writes them again without grading. --due,
--late-policy and --extensions charge late work; the changes in GRADES.adjustments.csv
beside the CSV
(id,task,change,reason[,note: private]) are applied at every rendering. These
options and files are checked whole before anything is graded: every mistake is
named with its line and the fix. A submission graded again
gets its row replaced; --resume grades only those not yet graded with the same checks
and files, and those the grader failed on. Ctrl-C or SIGTERM stops the run at once,
keeping what was graded. A failure of the grader or the machine, on evidence the
submission cannot produce (a sandbox ended from outside its namespaces, a sandbox or
judge kept waiting for a processor), is graded again (--retries), never blamed on the
student; whatever the submission's own process does (exits, ends itself by a signal,
sleeps, loops) is its own outcome. The summary gives the run's processor time (grader,
judges, sandboxes) and the rows graded more than once. Exit status 0 if every submission
was graded, 1 if some could not be (their notes say why), 2 if the grader itself failed
(named in the notes: no student feedback file is written for those submissions; run
again with --resume), 130 if interrupted (143 by SIGTERM). With --cluster ADDRESS the
submissions are graded by a Dask scheduler's workers (msdlab[cluster]).
"""

from __future__ import annotations

import argparse
import dataclasses
import os
import signal
import sqlite3
import sys
import time
from pathlib import Path

from tqdm.auto import tqdm

from ...analysis.cluster import parse_cluster
from ...course import PROJECT_ROOT, TASKS, own_numbers
from .. import intake
from ..intake import copied_numbers
from ..judging import grading, sandbox
from ..judging.cluster_grading import grade_all_on_cluster
from ..judging.temporary_paths import scrub
from ..outputs import class_report, render
from ..points import gradebook, gradebook_db
from ..rules import adjustments, final_points, problems, term_options
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
        "--roster",
        type=Path,
        default=None,
        help="the class: a CSV whose first line names its columns, 'id' and 'folder' (the "
        "folder or zip handed in); with SUBMISSIONs, each one's id must be a roster id",
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
        "--task-timeout",
        type=float,
        default=60.0,
        help="processor seconds a submission's code may take for each function in one task's "
        "checks, all its calls together: an endless loop costs this once, however busy the "
        "machine, and the task's other functions keep their own (%(default)s)",
    )
    parser.add_argument(
        "--call-timeout",
        type=float,
        default=300.0,
        help="seconds of its own one call into it may take: wall-clock time, less the time its "
        "sandbox waited for a processor or for the judge; the same at any load (%(default)s)",
    )
    parser.add_argument(
        "--retries",
        type=int,
        default=2,
        help="times a submission is graded again after a failure of the grader or the "
        "machine, not the student's (%(default)s)",
    )
    parser.add_argument(
        "--render",
        action="store_true",
        help="grade nothing: write the grades file (and with --feedback the feedback files and "
        "summary) again from the gradebook GRADES.db",
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
    if args.render:
        return render_views(args)
    if not (args.checks / "conftest.py").is_file() and not list(args.checks.glob("test_*.py")):
        raise FileNotFoundError(f"no checks in {args.checks}; give --checks DIR")
    if args.jobs < 1 or args.timeout <= 0 or args.call_timeout <= 0 or args.memory < 256:
        raise ValueError("--jobs >= 1, --timeout and --call-timeout > 0 and --memory >= 256 MB")
    if args.task_timeout <= 0 or args.retries < 0:
        raise ValueError("--task-timeout > 0 s and --retries >= 0")
    problem = sandbox.isolation_problem(args.isolation)
    if problem is not None:
        print(f"msdlab grade: {problem}", file=sys.stderr)
        return 2
    if not args.roster and not args.submissions:
        raise ValueError("give SUBMISSION folders or zip files, or --roster FILE")
    if args.similarity:
        similarity.require_copydetect()
    connection = open_gradebook(args.out)
    before = signal.signal(signal.SIGTERM, _terminate)
    try:
        session = Session(args, connection, checked_terms(args, connection))
        run_number = gradebook_db.start_run(connection, ["msdlab", *sys.argv[1:]])
        try:
            return session.grade(run_number)
        except KeyboardInterrupt as stop:
            for number in (signal.SIGINT, signal.SIGTERM):  # a second one: the views get out
                signal.signal(number, signal.SIG_IGN)
            gradebook_db.end_run(connection, run_number, "interrupted")
            session.render()
            print(session.interrupted(), file=sys.stderr)
            return 128 + (signal.SIGTERM if isinstance(stop, Terminated) else signal.SIGINT)
    finally:
        signal.signal(signal.SIGTERM, before)
        connection.close()


class Terminated(KeyboardInterrupt):
    """SIGTERM arrived: the run ends as at Ctrl-C (every judge and sandbox ended, the
    temporary folders removed, the run closed in the gradebook), with exit status 143."""


def _terminate(signum: int, frame: object) -> None:
    raise Terminated


def checked_terms(args: argparse.Namespace, connection: sqlite3.Connection) -> final_points.Terms:
    """The run's terms (`term_options.terms`); every mistake of the options and files that
    shows before the intake (manual changes beyond what a task is worth included) refused
    at once. The students' ids are checked after the intake (`Session`)."""
    terms, mistakes = term_options.terms(args)
    path = adjustments.beside(args.out)
    if path.is_file():
        maximum = render.grades_file(gradebook_db.read_records(connection), {}, False).maximum
        worth = term_options.possible_points(maximum, args.checks.resolve())
        changes = [change for listed in terms.changes.values() for change in listed]
        mistakes += adjustments.against_class(changes, str(path), worth, None)
    problems.settle(mistakes)
    return terms


def open_gradebook(out: Path) -> sqlite3.Connection:
    """The gradebook beside ``out``; on its first use, the rows of an older grades file
    ``out`` are taken in (their adjustments file stays where it is, read every run)."""
    connection = gradebook_db.connect(gradebook_db.beside(out))
    with gradebook_db.transaction(connection):
        taken = connection.execute("SELECT value FROM meta WHERE key = 'imported'").fetchone()
        if taken is None and Path(out).is_file():
            book = gradebook.Gradebook.load(out)
            for row in book.rows.values():
                gradebook_db.record_imported(connection, row, book.maximum)
            print(f"took {len(book.rows)} rows of {out} into the gradebook "
                  f"{gradebook_db.beside(out)}", file=sys.stderr)  # fmt: skip
        connection.execute("INSERT OR REPLACE INTO meta VALUES ('imported', ?)", (str(out),))
    return connection


def render_views(args: argparse.Namespace) -> int:
    """``--render``: the views of the gradebook written again, without grading."""
    if not gradebook_db.beside(args.out).is_file() and not args.out.is_file():
        raise FileNotFoundError(f"no gradebook at {gradebook_db.beside(args.out)} to render")
    connection = open_gradebook(args.out)
    try:
        terms = checked_terms(args, connection)
        records = render.render(connection, args.out, terms, args.feedback, args.detail, page=True)
    finally:
        connection.close()
    print(f"{len(records)} rows rendered from {gradebook_db.beside(args.out)} into {args.out}"
          + (f" and {args.feedback}" if args.feedback else ""))  # fmt: skip
    return 0


class Session:
    """One grading run: its submissions, what it has committed, and the views it renders."""

    def __init__(
        self, args: argparse.Namespace, connection: sqlite3.Connection, terms: final_points.Terms
    ) -> None:
        self.args, self.connection, self.terms = args, connection, terms
        self.run_number: int | None = None
        self.entries: dict[str, intake.Entry] = {}
        self.prints: dict[str, str] = {}
        self.graded: list[grading.Grade] = []
        self.todo: list[intake.Entry] = []
        self.own_numbers = False
        self.refused: list[str] = []

    def grade(self, run_number: int) -> int:
        """Grade the submissions, committing each as it is graded; the exit status."""
        args, self.run_number = self.args, run_number
        checks = args.checks.resolve()
        self.own_numbers = own_numbers_of(checks, args)
        rules = term_options.rules(args, self.terms)
        with intake.taken_in(args.submissions, args.roster, rules) as found:
            self.entries = {entry.id: entry for entry in found.entries}
            self.refused = found.refused
            self._say_what_the_intake_found(found)
            self.prints = {  # nothing is read from a submission refused at intake (a link, ...)
                i: gradebook.fingerprint(checks, e.folder)
                for i, e in self.entries.items()
                if e.problem is None
            }
            self.todo = self._todo()
            unusable = self._take_unusable()
            started = time.monotonic()
            grades = self._grade_todo(checks)
            gradebook_db.end_run(self.connection, run_number, "finished")
            self.render()
            if args.similarity:
                folders = {i: e.folder for i, e in self.entries.items() if e.problem is None}
                similarity.write_report(
                    folders,
                    args.out.parent / "similarity",
                    left_out_before=similarity.left_out_at(found),
                )
        return self._report(unusable + grades, time.monotonic() - started)

    def _mistakes(self, todo: list[intake.Entry]) -> list[problems.Problem]:
        """The mistakes of the instructor's files that only the class shows: manual changes
        naming an id no submission has (a lookalike refused), a student graded again
        without the due date their row was charged against."""
        records = gradebook_db.read_records(self.connection)
        path = adjustments.beside(self.args.out)
        known = {*self.entries, *(record.id for record in records)}
        changes = [c for listed in self.terms.changes.values() for c in listed]
        found = adjustments.against_class(changes, str(path), None, known)
        found += term_options.extensions_against_class(self.args, self.terms, known)
        rows = {record.id: record.final for record in records}
        regraded = [entry.id for entry in todo]
        where = str(gradebook_db.beside(self.args.out))
        return found + final_points.forgotten_due(rows, regraded, self.terms, where)

    def _say_what_the_intake_found(self, found: intake.Intake) -> None:
        """Put the hand-in times into the terms; print the submissions refused for their id
        and the count of hand-in times not verified."""
        handed = {i: e.handed_in for i, e in self.entries.items() if e.handed_in is not None}
        self.terms.handed_in.update(handed)
        for line in found.refused:
            print(line, file=sys.stderr)
        if self.terms.due is not None and term_options.unverified(found.entries):
            print(term_options.unverified(found.entries), file=sys.stderr)

    def _take_unusable(self) -> list[grading.Grade]:
        """Commit the rows of submissions with nothing to grade (absent, refused)."""
        unusable = []
        for entry in (e for e in self.entries.values() if e.problem is not None):
            grade = grading.Grade(entry.id, None, [entry.problem])
            status = gradebook_db.ABSENT if entry.absent else gradebook_db.NOT_GRADED
            self._commit(shown(grade, entry), status)
            where = f" (nothing at {entry.source})" if entry.absent and entry.source.name else ""
            print(f"{entry.id}: {entry.problem}{where}", file=sys.stderr)
            unusable.append(grade)
        return unusable

    def _todo(self) -> list[intake.Entry]:
        """The entries to grade: all, or with --resume those not graded with the same checks
        and files (the grader's failures among them)."""
        todo = [e for e in self.entries.values() if e.problem is None]
        if self.args.resume:
            known = gradebook_db.statuses(self.connection)
            todo = [e for e in todo if known.get(e.id) != (gradebook_db.GRADED, self.prints[e.id])]
        problems.settle(self._mistakes(todo))  # before anything is graded or committed
        skipped = sum(e.problem is None for e in self.entries.values()) - len(todo)
        address, jobs = parse_cluster(self.args.cluster) if self.args.cluster else (None, None)
        where = f"on the cluster {address}" if address else f"{jobs or self.args.jobs} at a time"
        plural = "" if len(todo) == 1 else "s"
        resumed = f" ({skipped} unchanged since graded, skipped)" if skipped else ""
        print(f"grading {len(todo)} submission{plural}{resumed}, {where}", file=sys.stderr)
        return todo

    def _grade_todo(self, checks: Path) -> list[grading.Grade]:
        args = self.args
        address, jobs = parse_cluster(args.cluster) if args.cluster else (None, args.jobs)
        options = dict(
            timeout=args.timeout,
            call_timeout=args.call_timeout,
            task_timeout=args.task_timeout,
            memory_mb=args.memory,
            isolation=args.isolation,
            allow_delegation=_tasks(args.allow_delegation),
            own_numbers=self.own_numbers,
        )
        graded = [grading.Submission(e.id, e.folder) for e in self.todo]
        if not graded:
            return []
        if address is not None:
            return grade_all_on_cluster(graded, checks, address, progress=self._progress, **options)
        return grading.grade_all(
            graded, checks, jobs=jobs, progress=self._progress, retries=args.retries, **options
        )

    def _progress(self, grade: grading.Grade, done: int, count: int) -> None:
        """Commit ``grade`` at once and say so (the views are rendered once, at the end of
        the run or at its interrupt, over the whole class)."""
        entry = self.entries[grade.submission]
        self._commit(shown(grade, entry), _status(grade), grade, self._hint(grade))
        self.graded.append(grade)
        width = max(len(identifier) for identifier in self.entries)
        if grade.graded:
            result = f"{grade.total}/{grade.report.points} points"
        else:
            result = "NOT GRADED: " + "; ".join(grade.notes)
        attempts = f", {grade.attempts} attempts" if grade.attempts > 1 else ""
        tqdm.write(f"[{done:>{len(str(count))}}/{count}] {grade.submission:<{width}}  "
                   f"{result}  ({grade.seconds:.1f} s{attempts})", file=sys.stderr)  # fmt: skip

    def _hint(self, grade: grading.Grade) -> str | None:
        """With own numbers, for the instructor only: whose task 1 constants a graded
        submission holds if not its author's (`copied_numbers`); said on stderr too."""
        if not (self.own_numbers and grade.graded):
            return None
        everyone = set(gradebook_db.statuses(self.connection)) | set(self.entries)
        folder = self.entries[grade.submission].folder
        hint = copied_numbers.hint(grade.submission, folder, everyone)
        if hint is not None:
            tqdm.write(f"{grade.submission}: {hint}", file=sys.stderr)
        return hint

    def _commit(
        self,
        grade: grading.Grade,
        status: str,
        raw: grading.Grade | None = None,
        hint: str | None = None,
    ) -> None:
        """One transaction: the row of ``grade`` with its evidence (``hint``: for the
        instructor only)."""
        entry = self.entries[grade.submission]
        handed = self.terms.handed_in.get(grade.submission)
        when = handed.time.isoformat(timespec="seconds") if handed and handed.time else None
        result = gradebook_db.Result(
            grade.submission, intake.escaped(str(entry.source)), status,
            [scrub(note) for note in grade.notes], grade.report,
            self.prints.get(grade.submission), when, handed.source if handed else None,
            raw.seconds if raw else None, raw.attempts if raw else 1, hint,
        )  # fmt: skip
        gradebook_db.record(self.connection, result, self.run_number)

    def render(self) -> list[gradebook_db.Record]:
        """Write the views over the whole class, the class report's page included."""
        args = self.args
        return render.render(
            self.connection, args.out, self.terms, args.feedback, args.detail, page=True
        )

    def interrupted(self) -> str:
        """The one line an interrupted run prints."""
        left = len(self.todo) - len(self.graded)
        return (
            f"msdlab grade: interrupted: {len(self.graded)} of {len(self.todo)} submissions "
            f"graded this run are saved in {gradebook_db.beside(self.args.out)}; run the same "
            f"command with --resume to grade the other {left}"
        )

    def _report(self, grades: list[grading.Grade], seconds: float) -> int:
        """Print the run's summary; its exit status."""
        args = self.args
        known = gradebook_db.statuses(self.connection)
        term_options.report(self.terms, args.out)
        print(grading.summary(grades, seconds, grading.grader_seconds()))
        if args.isolation != "namespace":
            print(f"isolation: {args.isolation} (weaker than namespace; submissions were not "
                  "isolated by the operating system)")  # fmt: skip
        kept = len(known) - len(grades)
        earlier = f" ({kept} rows of earlier runs kept)" if kept else ""
        print(f"grades written to {args.out}{earlier}")
        print(f"class report written to {class_report.beside(args.out)}")
        failed = [grade for grade in grades if grade.grader_failed]
        if failed:
            print(grader_failure(failed), file=sys.stderr)
            return 2
        if self.refused:
            print(f"{len(self.refused)} submission{'s' * (len(self.refused) > 1)} refused for "
                  "their id (no row; see above)", file=sys.stderr)  # fmt: skip
        everyone = all(grade.graded or self._absent(grade) for grade in grades)
        return 0 if everyone and not self.refused else 1

    def _absent(self, grade: grading.Grade) -> bool:
        return self.entries[grade.submission].absent


def _status(grade: grading.Grade) -> str:
    if grade.grader_failed:
        return gradebook_db.GRADER_FAILED
    return gradebook_db.GRADED if grade.graded else gradebook_db.NOT_GRADED


def own_numbers_of(checks: Path, args: argparse.Namespace) -> bool:
    """Whether each student is graded against their own numbers: the setting of the course
    ``checks`` belong to. Refused where that course has no setting but the installed course
    has them on (``--checks`` outside the course would turn them off silently), or where no
    roster names the students (their numbers follow the roster id, not a path)."""
    course = own_numbers.course_of(checks)
    settings = course / own_numbers.SETTINGS_FILE
    if not settings.is_file() and own_numbers.enabled(PROJECT_ROOT):
        raise ValueError(
            f"{PROJECT_ROOT / own_numbers.SETTINGS_FILE} gives each student their own numbers, "
            f"but the checks {checks} lie outside that course (no {settings}): copy "
            f"{own_numbers.SETTINGS_FILE} to {course}, or give --checks inside the course"
        )
    own = own_numbers.enabled(course)
    if own and not args.roster:
        raise ValueError(
            f"{settings} gives each student their own numbers, which follow the roster id: "
            "give --roster FILE (a first line 'id,folder', then one line per student) so each "
            "submission is graded against its owner's numbers, not a path's"
        )
    where = settings if settings.is_file() else f"no {settings}"
    print(f"own numbers: {'on' if own else 'off'} ({where})", file=sys.stderr)
    return own


def grader_failure(failed: list[grading.Grade]) -> str:
    """What to tell the instructor when the grader itself failed on ``failed``."""
    note = next(n for n in failed[0].notes if n.startswith(grading.GRADER_ERROR))
    plural = "s" if len(failed) > 1 else ""
    names = ", ".join(grade.submission for grade in failed)
    return (
        f"msdlab grade: could not grade {len(failed)} submission{plural} ({names}), the "
        f"grader's failure and no fault of their authors, who got no feedback file: "
        f"{scrub(note)}. Run the same command with --resume to grade only those."
    )


def shown(grade: grading.Grade, entry: intake.Entry) -> grading.Grade:
    """``grade`` with the intake's notes on its submission first (for the CSV and feedback)."""
    return dataclasses.replace(grade, notes=[*entry.notes, *grade.notes])


def _tasks(text: str) -> list[int]:
    """ "2,5" -> [2, 5]; a clear error for anything but task numbers."""
    parts = [part.strip().removeprefix("task") for part in text.split(",") if part.strip()]
    if not all(part.isdigit() and int(part) in TASKS for part in parts):
        raise ValueError(f"--allow-delegation takes task numbers {TASKS} like 2,5; got {text!r}")
    return [int(part) for part in parts]
