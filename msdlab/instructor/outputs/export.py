"""The class's grades in the form a learning management system imports.

The grades are read from the gradebook ``grades.db`` beside the grades file named (the
record of every grading run, a run stopped before it rendered its views included), or,
for a course graded before that database, from the grades file itself.

The roster is a CSV whose first line names its columns: ``id`` (the grades' id) and any
of ``name``, ``email``, ``sis_id``, ``sis_login_id``, ``section``, ``canvas_id``; other
columns (``folder``, say) are kept in the ``csv`` format. The same file can be the
roster ``msdlab grade --roster`` reads, with ``folder`` as its second column.

- ``canvas``: Canvas's gradebook import: ``Student, ID, SIS User ID, SIS Login ID,
  Section`` and one column for the assignment; its second line is Canvas's
  ``Points Possible`` row, the only line that is not a student.
- ``moodle``: for Moodle's "Import grades from CSV": ``Full name, ID number, Email
  address``, the assignment's points and a feedback line (how the total was made); map
  ``Email address`` or ``ID number`` to the user when importing.
- ``csv``: one row per student with the roster's columns, the task points, ``points``,
  ``late_penalty``, ``adjustment``, ``total``, ``status``, ``max_points``, and ``source``
  relative to the exported file's folder.

A row the grader failed on (status ``grader failed``) has no points: its cells are left
empty in every format, never 0, and the console says so for each such student.
"""

from __future__ import annotations

import csv
import os
import sys
from pathlib import Path

from ...course import TASKS
from ..intake import escaped, unescaped
from ..points import gradebook_db
from ..points.gradebook import Gradebook
from ..rules import adjustments, final_points, problems
from ..rules.final_points import Terms
from . import render
from .csv_files import write_csv

FORMATS = ("canvas", "moodle", "csv")
ALIASES = {
    "name": ("name", "student", "full name"),
    "email": ("email", "email address"),
    "sis_id": ("sis_id", "sis id", "sis user id", "id number", "student number"),
    "sis_login_id": ("sis_login_id", "sis login id", "login"),
    "section": ("section",),
    "canvas_id": ("canvas_id", "canvas id"),
}
CANVAS_COLUMNS = ["Student", "ID", "SIS User ID", "SIS Login ID", "Section"]
POINTS_POSSIBLE = "    Points Possible"


def read_roster(path: Path) -> list[dict[str, str]]:
    """The roster's rows, their columns named as in `ALIASES` (others kept as written)."""
    path = Path(path)
    if not path.is_file():
        raise FileNotFoundError(f"no roster file at {path}")
    with path.open(newline="", encoding="utf-8-sig") as handle:
        reader = csv.DictReader(handle)
        names = {c: _standard(c) for c in reader.fieldnames or []}
        if "id" not in names.values():
            raise ValueError(
                f"{path}: the first line must name the columns, e.g. 'id,folder,name,email,sis_id'"
            )
        rows = [{names[k]: (v or "").strip() for k, v in row.items() if k} for row in reader]
    return [row for row in rows if row.get("id") and not row["id"].startswith("#")]


def _standard(column: str) -> str:
    plain = column.strip().lower()
    if plain == "id":
        return "id"
    return next((key for key, names in ALIASES.items() if plain in names), column.strip())


def table(
    grades: Path, roster: list[dict[str, str]] | None, form: str, assignment: str, out: Path
) -> list[list[str]]:
    """The lines of the export of ``grades`` in the format ``form``."""
    book = settled(grades)
    people = roster if roster is not None else [{"id": i} for i in book.rows]
    _warn_unmatched(book, people, grades)
    _warn_no_points(book, {person["id"] for person in people})
    if form == "canvas":
        return _canvas(book, people, assignment)
    if form == "moodle":
        return _moodle(book, people, assignment)
    return _plain(book, people, out)


def settled(grades: Path) -> Gradebook:
    """The grades file ``grades`` with every row's total settled as ``msdlab grade`` settles
    it (`final_points.settle`): the manual changes written since the last run count, and a
    mistake in them stops the export as it stops grading."""
    book = class_of(grades)
    if not book.rows:
        raise ValueError(f"{grades} holds no grades; run msdlab grade --out {grades} first")
    path = adjustments.beside(grades)
    changes, found = adjustments.parse(path)
    maximum = final_points.worth(book.maximum)
    found += adjustments.problems(changes, str(path))
    problems.settle(found + adjustments.against_class(changes, str(path), maximum, set(book.rows)))
    final_points.settle(book.rows, Terms(changes=adjustments.by_student(changes)))
    return book


def class_of(grades: Path) -> Gradebook:
    """The class's rows as ``msdlab grade`` last settled them: from the gradebook beside
    ``grades`` if it holds any, else from the grades file ``grades`` (an older course's)."""
    if gradebook_db.beside(grades).is_file():
        records = gradebook_db.read_class(grades)
        if records:
            rows = {record.id: render.row_of(record) for record in records}
            return render.grades_file(records, rows, detail=False)
    return Gradebook.load(grades)


def _warn_unmatched(book: Gradebook, people: list[dict[str, str]], grades: Path) -> None:
    listed = {person["id"] for person in people}
    for identifier in sorted(set(book.rows) - listed):
        print(f"warning: {identifier!r} has grades but is not in the roster: left out",
              file=sys.stderr)  # fmt: skip
    for identifier in sorted(listed - set(book.rows)):
        print(f"warning: {identifier!r} is in the roster but not in {grades}: no grade given, "
              "the cell is left empty (an LMS keeps the grade it had); msdlab grade --roster "
              "gives a student who handed in nothing a row of 0", file=sys.stderr)  # fmt: skip


def _warn_no_points(book: Gradebook, exported: set[str]) -> None:
    """Say which exported rows have no points because the grader failed on them."""
    for identifier in sorted(exported & set(book.rows)):
        if book.rows[identifier].get("status") == gradebook_db.GRADER_FAILED:
            print(f"warning: {identifier!r}: the grader failed on this submission (not the "
                  "student's failure): no points exported, the cell is left empty (an LMS "
                  "keeps the grade it had); run msdlab grade again with --resume",
                  file=sys.stderr)  # fmt: skip


def _warn_unnamed(people: list[dict[str, str]], keys: tuple[str, ...], form: str) -> None:
    """Warn of each student the LMS cannot match: none of the roster's ``keys`` given."""
    for person in people:
        if not any(person.get(key) for key in keys):
            print(f"warning: {person['id']!r} has none of {', '.join(keys)} in the roster: "
                  f"{form} cannot tell whose grade it is", file=sys.stderr)  # fmt: skip


def _canvas(book: Gradebook, people: list[dict[str, str]], assignment: str) -> list[list[str]]:
    _warn_unnamed(people, ("canvas_id", "sis_id", "sis_login_id"), "Canvas")
    lines = [[*CANVAS_COLUMNS, assignment], [POINTS_POSSIBLE, "", "", "", "", _maximum(book)]]
    for person in people:
        row = book.rows.get(person["id"], {})
        lines.append([person.get("name") or person["id"], person.get("canvas_id", ""),
                      person.get("sis_id", ""), person.get("sis_login_id", ""),
                      person.get("section", ""), row.get("total", "")])  # fmt: skip
    return lines


def _moodle(book: Gradebook, people: list[dict[str, str]], assignment: str) -> list[list[str]]:
    _warn_unnamed(people, ("email", "sis_id"), "Moodle")
    lines = [["Full name", "ID number", "Email address", assignment, "Feedback"]]
    for person in people:
        row = book.rows.get(person["id"], {})
        lines.append([person.get("name") or person["id"], person.get("sis_id", ""),
                      person.get("email", ""), row.get("total", ""), _how(row)])  # fmt: skip
    return lines


def _how(row: dict[str, str]) -> str:
    """How the total was made, in a line: checks, late penalty, adjustment ('' for a row
    without a total: none, or the grader's failure)."""
    if not row.get("total"):
        return ""
    parts = [f"checks {row.get('points') or row.get('total', '')}"]
    if row.get("late_penalty"):
        parts.append(f"late penalty {row['late_penalty']}")
    if row.get("adjustment"):
        parts.append(f"adjustment {row['adjustment']}")
    return ", ".join(parts) + f"; total {row.get('total', '')}"


def _plain(book: Gradebook, people: list[dict[str, str]], out: Path) -> list[list[str]]:
    personal = list(dict.fromkeys(key for person in people for key in person))
    points = [f"task{t}" for t in TASKS] + ["points", "late_penalty", "adjustment", "total",
                                            "status"]  # fmt: skip
    lines = [[*personal, "source", *points, "max_points"]]
    for person in people:
        row = book.rows.get(person["id"], {})
        source = _relative(row["source"], out.parent) if row.get("source") else ""
        lines.append([person.get(key, "") for key in personal]
                     + [source, *(row.get(key, "") for key in points), _maximum(book)])  # fmt: skip
    return lines


def _maximum(book: Gradebook) -> str:
    return book.maximum.get("total", "")


def _relative(source: str, folder: Path) -> str:
    """The escaped path ``source`` relative to ``folder`` (as it was if on another drive)."""
    try:
        return escaped(os.path.relpath(unescaped(source), os.path.abspath(folder)))
    except ValueError:
        return source


def write(lines: list[list[str]], path: Path) -> None:
    """The lines as a UTF-8 CSV file at ``path`` (no cell a spreadsheet takes for a formula;
    the first line, the columns' names, included)."""
    write_csv(path, lines[1:], header=lines[0])
