"""The views of the gradebook: the grades file, the feedback files and the summary.

`render` settles every row of the gradebook (`final_points`: late work, manual changes),
stores what it settled, and writes the views over the whole class, all inside one write
transaction of the database: two runs rendering into one folder write one after the other,
and the views the later one writes hold both runs' rows.

- ``grades.csv`` (`gradebook.Gradebook`): one row per submission, the maximum's row first.
- with a feedback folder: ``students/ID.md`` to hand out (none where the grader failed),
  ``instructor/ID.md`` with everything, and ``summary.md`` over the whole class, the
  class at a glance (`class_report.summary_section`) at its end.
- ``grades.class.html`` (`class_report`), at the end of a run and on ``--render``.
"""

from __future__ import annotations

import os
import sqlite3
from pathlib import Path

from ...course import TASKS
from ...course.report import CheckReport
from .. import intake
from ..judging.grading import Grade
from ..judging.temporary_paths import scrub
from ..points import gradebook_db
from ..points.gradebook import Gradebook, check_column
from ..points.gradebook_db import GRADED, GRADER_FAILED, Record
from ..rules import adjustments, final_points
from . import class_report, feedback, output_files


def render(
    connection: sqlite3.Connection,
    out: Path,
    terms: final_points.Terms,
    feedback_folder: Path | None = None,
    detail: bool = False,
    page: bool = False,
) -> list[Record]:
    """Settle every row with ``terms``, store it, and write the views (see the module
    docstring; ``page``: the class report's page too, which takes a second or two for its
    pictures); the gradebook's records, settled."""
    with gradebook_db.transaction(connection):
        records = gradebook_db.read_records(connection)
        rows = {record.id: row_of(record) for record in records}
        explained = final_points.settle(rows, terms)
        for record in records:
            row = rows[record.id]
            record.final = {key: row.get(key, "") for key in [*gradebook_db.SETTLED, "total"]}
            record.explained = explained[record.id]
            gradebook_db.store_final(connection, record.id, row, record.explained)
        gradebook_db.store_changes(connection, terms.changes)
        book = grades_file(records, rows, detail)
        book.write(out)
        grades = [grade_of(record) for record in records]
        at_a_glance = class_report.rows_of(book, grades)
        if page:
            class_report.write_html(at_a_glance, book.maximum, class_report.beside(out))
        if feedback_folder is not None:
            link = os.path.relpath(class_report.beside(out), feedback_folder)
            section = class_report.summary_section(at_a_glance, link)
            private = adjustments.private_notes(terms.changes)
            write_feedback(Path(feedback_folder), records, rows, book, section, private)
    return records


def row_of(record: Record) -> dict[str, str]:
    """The grades file's row of ``record``, before the term's rules are applied (the late
    columns of the last settling kept: a run without ``--due`` charges no new penalty)."""
    row = {"id": record.id, "source": record.source, "status": record.status}
    nothing = "" if record.status == GRADER_FAILED else "0"  # the grader's failure: no points
    row.update({f"task{t}": record.tasks.get(t, (nothing, "0"))[0] for t in TASKS})
    row.update(record.final)
    row["points"] = ""  # from the task points, settled again
    row["handed_in"] = record.handed_in or ""
    row["handed_in_from"] = record.handed_in_from or ""
    row["notes"] = scrub("; ".join(record.notes))
    row["fingerprint"] = (record.fingerprint or "") if record.status == GRADED else ""
    for check in record.checks:
        row[check_column(check.task, check.name)] = str(check.earned)
    return row


def grades_file(records: list[Record], rows: dict[str, dict[str, str]], detail: bool) -> Gradebook:
    """The grades file of ``records`` (``detail``: a column per check)."""
    book = Gradebook()
    latest = max((r for r in records if r.checks or r.tasks), key=_when, default=None)
    if latest is not None:
        book.maximum.update({f"task{t}": latest.tasks.get(t, ("", "0"))[1] for t in TASKS})
        possible = sum(int(latest.tasks.get(t, ("", "0"))[1]) for t in TASKS)
        book.maximum["points"] = book.maximum["total"] = str(possible)
    if detail and latest is not None:
        for check in latest.checks:
            column = check_column(check.task, check.name)
            book.maximum[column] = str(check.points)
            book.detail_columns.append(column)
    book.rows = rows
    return book


def _when(record: Record) -> tuple[bool, str]:
    return bool(record.checks), record.graded_at


def grade_of(record: Record) -> Grade:
    """The `Grade` that ``record`` holds (for the feedback)."""
    report = CheckReport(record.source, list(record.checks)) if record.checks else None
    return Grade(record.id, report, list(record.notes), record.seconds or 0.0)


def write_feedback(
    folder: Path,
    records: list[Record],
    rows: dict[str, dict[str, str]],
    book: Gradebook,
    class_section: str = "",
    private: dict[str, list[str]] | None = None,
) -> None:
    """Every submission's feedback files and the summary, ``class_section`` at its end (see
    the module docstring; ``private``: lines by id only the instructor's file shows, the
    adjustments' notes); a row imported from an older grades file keeps the files it had,
    with its section on late work and manual changes brought up to date."""
    private = private or {}
    for kind in ("students", "instructor"):
        output_files.not_a_link(folder / kind, "feedback folder")
        (folder / kind).mkdir(parents=True, exist_ok=True)
    possible = book.maximum.get("total", "")
    for record in records:
        stem = intake.file_stem(record.id)
        student = folder / "students" / f"{stem}.md"
        instructor = folder / "instructor" / f"{stem}.md"
        section = final_points.feedback_section(rows[record.id], record.explained, possible)
        if record.status == GRADED and not record.checks:
            final_points.refresh_feedback(folder, {record.id: rows[record.id]},
                                          {record.id: record.explained}, possible,
                                          private)  # fmt: skip
            continue
        grade = grade_of(record)
        if record.status == GRADER_FAILED:  # nothing to hand out: the grader's failure
            student.unlink(missing_ok=True)
        else:
            source = intake.unescaped(record.source)
            text = feedback.for_student(grade, rows[record.id].get("total"), source)
            _write(student, final_points.with_section(text, section))
        text = feedback.for_instructor(grade, record.source, record.hint)
        noted = [*record.explained, *private.get(record.id, [])]
        own_section = final_points.feedback_section(rows[record.id], noted, possible)
        _write(instructor, final_points.with_section(text, own_section))
    grades = [grade_of(record) for record in records]
    summary = feedback.class_summary(book, records, grades) + class_section
    _write(folder / "summary.md", summary)


def _write(path: Path, text: str) -> None:
    """Write ``text`` unless the file holds it already (a link is refused, never read)."""
    output_files.not_a_link(path, "feedback file")
    if not path.is_file() or path.read_text(encoding="utf-8") != text:
        output_files.write_text(path, text, "feedback file")
