"""Feedback files of a grading run: one to hand to each student, one for the instructor.

- `for_student`: the final total first (the term's rules applied; how it was reached in
  the section below it), the public checks in full (points, result, what a failing one
  saw); hidden checks only as "N hidden checks: P of Q points" per task, with no name,
  message or generated input; a task not attempted (or whose file did not load) as one
  line; no path of the grader's temporary folders and no note about the grader itself
  (`student_notes`). Gradescope's results say the same (`judging.gradescope`).
- `for_instructor`: every check with its full message, and the grading notes.
- `class_summary`: over the whole class, the score distribution per task, the checks
  failed most often, and who handed in nothing or could not be graded.
"""

from __future__ import annotations

import collections
import os
import re
import statistics
from collections.abc import Sequence
from fractions import Fraction
from typing import TYPE_CHECKING

from ...course import TASKS
from ...course.report import CheckResult, without_mistake
from ..intake import NOT_ON_ROSTER
from ..judging.grading import Grade
from ..judging.temporary_paths import scrub
from ..points.gradebook_db import ABSENT, GRADER_FAILED

GRADER_ONLY = ("graded with the weaker isolation",)
"""How the notes the grader makes about itself start: the instructor's, not a student's."""

if TYPE_CHECKING:
    from ..points.gradebook import Gradebook
    from ..points.gradebook_db import Record


def for_student(grade: Grade, total: str | None = None, source: str = "") -> str:
    """The Markdown feedback a student may read, opening with the final ``total`` (the
    term's rules applied; None: the checks' points are the total); paths in it are
    relative, as seen from above the folder of the hand-in ``source`` (`student_notes`)."""
    lines = [f"# Feedback: {grade.submission}", ""]
    if grade.report is None:
        lines += ["Your submission could not be graded:", ""]
        lines += [f"- {note}" for note in student_notes(grade.notes, source)]
        return "\n".join(lines) + "\n"
    report = grade.report
    public = [c for c in report.checks if not c.hidden]
    hidden = [c for c in report.checks if c.hidden]
    final = total if total not in (None, "") else str(grade.total)
    changed = Fraction(final) != grade.total
    lines.append(
        f"**{final} of {report.points} points**"
        + (f" (the checks gave {grade.total}; late work and manual changes below)" * changed)
        + f": public checks {_earned(public)} of {_points(public)}, hidden checks "
        f"{_earned(hidden)} of {_points(hidden)}."
    )
    lines += ["", *[f"Note: {note}" for note in student_notes(grade.notes, source)]]
    for task in report.tasks():
        checks = [c for c in report.checks if c.task == task]
        lines += ["", _task_heading(task, checks)]
        reason = _one_reason(checks)
        if reason is not None:
            lines.append(reason)
            continue
        lines.append("")
        named: dict[str, str] = {}  # a recognised mistake -> the check that named it first
        for check in (c for c in checks if not c.hidden):
            lines.append(f"- {check.name}: {check.earned} of {check.points} points, "
                         f"{'passed' if check.passed else check.outcome}")  # fmt: skip
            if not check.passed:
                message = _message(check)
                if check.mistake in named:  # one mistake, named once
                    message = f"{without_mistake(message, check.mistake)} The same mistake as "
                    message += f"in {named[check.mistake]}."
                elif check.mistake:
                    named[check.mistake] = check.name
                lines += [f"  > {scrub(line)}" for line in message.splitlines() if line]
        secret = [c for c in checks if c.hidden]
        if secret:
            lines.append(
                f"- {len(secret)} hidden checks: {_earned(secret)} of {_points(secret)} points"
            )
    return "\n".join(lines) + "\n"


def student_notes(notes: Sequence[str], source: str = "") -> list[str]:
    """The notes a student reads: without the grader's own (how it isolated the checks),
    with no path of the grader's temporary folders, and paths below the folder that holds
    the hand-ins' folder (of the hand-in ``source``) relative to it: ``class/alice``, not
    the instructor's whole path."""
    above = os.path.dirname(os.path.dirname(source.rstrip("/")))
    kept = [scrub(note) for note in notes if not note.startswith(GRADER_ONLY)]
    return [note.replace(above + "/", "") if len(above) > 1 else note for note in kept]


def for_instructor(grade: Grade, source: str = "", hint: str | None = None) -> str:
    """The Markdown feedback with everything: notes, every check and every message, and a
    ``hint`` for the instructor only (whose own numbers the submission holds)."""
    lines = [f"# {grade.submission}", ""]
    if source:
        lines += [f"Handed in: {_code(source)}", ""]
    if hint:
        lines += [f"For you only: {hint}", ""]
    if grade.report is None:
        lines += ["Not graded:", *[f"- {note}" for note in grade.notes]]
        return "\n".join(lines) + "\n"
    points = ", ".join(f"task{t} {grade.points(t)}" for t in TASKS)
    lines += [f"{grade.total}/{grade.report.points} points ({points}), "
              f"graded in {grade.seconds:.1f} s", ""]  # fmt: skip
    lines += [f"Note: {note}" for note in grade.notes]
    lines += ["", *_block(scrub(grade.report.table())), ""]
    details = grade.report.details()
    if details:
        lines += ["## What the failing checks saw", "", *_block(scrub(details))]
    return "\n".join(lines) + "\n"


def class_summary(book: Gradebook, records: Sequence[Record], grades: Sequence[Grade]) -> str:
    """Markdown over the whole class: per task the spread of points, the checks failed most
    often (over every submission the gradebook has check results of, ``grades``), and the
    submissions that were absent or that the grader could not grade."""
    graded = book.graded_rows()
    lines = ["# Grading summary", "", f"{len(graded)} of {len(records)} submissions graded.", ""]
    absent = [r.id for r in records if r.status == ABSENT]
    if absent:
        lines += [f"Nothing handed in ({len(absent)}): {', '.join(absent)}.", ""]
    unlisted = [r.id for r in records if any(NOT_ON_ROSTER in note for note in r.notes)]
    if unlisted:
        lines += [f"Handed in under an id not on the roster, not graded ({len(unlisted)}): "
                  f"{', '.join(unlisted)}.", ""]  # fmt: skip
    failed = [r.id for r in records if r.status == GRADER_FAILED]
    if failed:
        lines += [f"Could not be graded, the grader's failure and not the students' "
                  f"({len(failed)}): {', '.join(failed)}. Run the same command with "
                  "--resume to grade them again.", ""]  # fmt: skip
    if not graded:
        return "\n".join(lines)
    lines += ["| task | points | mean | median | min | max | how many got how many points |",
              "| --- | --- | --- | --- | --- | --- | --- |"]  # fmt: skip
    for column in (*(f"task{task}" for task in TASKS), "total"):
        scores = [float(row[column]) for row in graded]
        spread = collections.Counter(scores)
        counts = ", ".join(f"{points:g}: {spread[points]}" for points in sorted(spread))
        lines.append(
            f"| {column} | {book.maximum[column]} | {statistics.mean(scores):.1f} | "
            f"{statistics.median(scores):g} | {min(scores):g} | {max(scores):g} | {counts} |"
        )
    return "\n".join(lines + _most_failed(graded, grades)) + "\n"


def _most_failed(graded: list[dict[str, str]], grades: Sequence[Grade]) -> list[str]:
    """The lines naming the ten checks failed most often, by how many submissions."""
    reports = [g.report for g in grades if g.report is not None]
    failed = collections.Counter(
        f"task{c.task} {c.name}" + (" (hidden)" if c.hidden else "")
        for report in reports
        for c in report.checks
        if not c.passed
    )
    heading = "Checks failed most often:"
    if len(reports) < len(graded):
        plural = "" if len(reports) == 1 else "s"
        heading = (
            f"Checks failed most often by the {len(reports)} submission{plural} with check "
            "results (rows taken in from an older grades file have none until graded again):"
        )
    common = [(name, count) for name, count in failed.most_common(10) if count]
    if not common:
        return []
    return [
        "",
        heading,
        "",
        *(f"- {name}: failed by {count} of {len(reports)}" for name, count in common),
    ]


def _task_heading(task: int, checks: list[CheckResult]) -> str:
    return f"## Task {task}: {_earned(checks)} of {_points(checks)} points"


def _one_reason(checks: list[CheckResult]) -> str | None:
    """One line for a task whose every check failed for the same reason (not attempted, a
    file that does not load), else None."""
    public = [c for c in checks if not c.hidden] or checks
    if any(c.passed for c in checks):
        return None
    if all(c.exception == "NotImplementedError" for c in public):
        return "Not attempted yet (every check found NotImplementedError)."
    reasons = {(c.exception, c.summary) for c in public}
    if len(reasons) == 1 and len(public) > 1:
        exception, summary = reasons.pop()
        if exception in ("SubmissionError", "FileNotFoundError", "SyntaxError"):
            return f"Every check stopped at: {scrub(summary)}"
    return None


def _fence(text: str, shortest: int) -> str:
    """Backticks one longer than any run in ``text``: what a student's message holds cannot
    close the code around it."""
    longest = max((len(run) for run in re.findall(r"`+", text)), default=0)
    return "`" * max(shortest, longest + 1)


def _block(text: str) -> list[str]:
    """``text`` as a fenced code block (Markdown), shown as written."""
    fence = _fence(text, 3)
    return [fence, text, fence]


def _code(text: str) -> str:
    """``text`` as inline code (Markdown), shown as written (the spaces inside are dropped)."""
    fence = _fence(text, 1)
    return f"{fence} {text} {fence}"


def _message(check: CheckResult) -> str:
    if check.exception and check.exception not in ("CheckFailed", "AssertionError"):
        return f"{check.exception}: {check.message}"
    return check.message or "(no message)"


def _earned(checks: Sequence[CheckResult]) -> int:
    return sum(c.earned for c in checks)


def _points(checks: Sequence[CheckResult]) -> int:
    return sum(c.points for c in checks)
