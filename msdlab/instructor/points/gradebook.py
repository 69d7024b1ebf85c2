"""The class's grades as a CSV file: one row per submission id, kept up to date across runs.

Columns: ``id``, ``source`` (the folder or zip handed in, named exactly: see
`intake.escaped`), ``task1`` ... ``task5`` (the checks' points), ``points`` (their sum),
the late work and manual changes (`final_points`), ``total``, ``status`` (graded, not graded,
absent, grader failed: `gradebook_db.STATUSES`; a row the grader failed on has no points
at all, never 0), optionally one column per check
(``--detail``: ``task2 rest_state_feels_no_force``), ``notes`` and ``fingerprint`` (a hash
of the checks and the submission's task files).
The first row, id ``(max points)``, holds what each column is worth.

Every write replaces the file atomically (`csv_files.write_csv`), so a crash leaves the
previous CSV or a complete new one; no cell is a formula to a spreadsheet, and every id
reads back exactly. Rows of earlier runs are kept; grading a submission again replaces
its row, and a submission whose fingerprint is unchanged can be skipped (``--resume``).
"""

from __future__ import annotations

import hashlib
from pathlib import Path

from ...course import TASKS
from ...course.report import CheckReport
from ..intake import MAX_POINTS_ID, Entry, escaped
from ..judging.grading import Grade
from ..judging.temporary_paths import scrub
from ..outputs.csv_files import read_csv, write_csv
from ..rules.final_points import COLUMNS as FINAL_COLUMNS

FIRST = ["id", "source", *(f"task{t}" for t in TASKS), *FINAL_COLUMNS, "total", "status"]
LAST = ["notes", "fingerprint"]


def fingerprint(checks: Path, folder: Path) -> str:
    """A hash of every file of the checks folder and of the submission's task files."""
    digest = hashlib.sha256()
    for base, pattern in ((Path(checks), "*.py"), (Path(folder), "task*.py")):
        for path in sorted(base.glob(pattern)):
            if path.is_file() and not path.is_symlink():
                digest.update(path.name.encode() + b"\0" + path.read_bytes() + b"\0")
        digest.update(b"\1")
    return digest.hexdigest()[:16]


def check_column(task: int, name: str) -> str:
    """The ``--detail`` column of a check."""
    return f"task{task} {name}"


class Gradebook:
    """The rows of the grades file by id (written sorted by id, after the maximum's row)."""

    def __init__(self) -> None:
        self.rows: dict[str, dict[str, str]] = {}
        self.maximum: dict[str, str] = {"id": MAX_POINTS_ID}
        self.detail_columns: list[str] = []

    @classmethod
    def load(cls, path: Path) -> Gradebook:
        """The gradebook in ``path`` (empty if there is none yet)."""
        book = cls()
        if not Path(path).exists():
            return book
        columns, *lines = read_csv(path) or [[]]
        if columns[:1] != ["id"] or "fingerprint" not in columns:
            raise ValueError(
                f"{path} is not a grades file written by msdlab grade; give another --out"
            )
        book.detail_columns = [c for c in columns if c not in FIRST and c not in LAST]
        for line in lines:
            values = dict(zip(columns, [*line, *[""] * (len(columns) - len(line))]))
            if values.get("id") == MAX_POINTS_ID:
                book.maximum = values
            elif values.get("id"):
                book.rows[values["id"]] = values
        return book

    def fingerprint_of(self, identifier: str) -> str | None:
        """The fingerprint of a submission graded earlier (None if never graded to the end)."""
        return (self.rows.get(identifier) or {}).get("fingerprint") or None

    def graded_rows(self) -> list[dict[str, str]]:
        """The rows of submissions graded to the end (those with a fingerprint)."""
        return [row for row in self.rows.values() if row.get("fingerprint")]

    def record(self, grade: Grade, entry: Entry, print_: str | None, detail: bool) -> None:
        """Put the row of ``grade`` in (replacing the row with the same id)."""
        row = {"id": grade.submission, "source": escaped(str(entry.source))}
        row.update({f"task{t}": str(grade.points(t)) for t in TASKS})
        row["points"] = row["total"] = str(grade.total)
        if grade.report is not None:
            self._maximum(grade.report, detail)
            if detail:
                row.update(
                    {check_column(c.task, c.name): str(c.earned) for c in grade.report.checks}
                )
        row["notes"] = scrub("; ".join(grade.notes))
        row["fingerprint"] = print_ if grade.graded and print_ else ""
        self.rows[grade.submission] = row

    def _maximum(self, report: CheckReport, detail: bool) -> None:
        for task in TASKS:
            self.maximum[f"task{task}"] = str(
                sum(c.points for c in report.checks if c.task == task)
            )
        self.maximum["points"] = self.maximum["total"] = str(report.points)
        if detail:
            for check in report.checks:
                column = check_column(check.task, check.name)
                self.maximum[column] = str(check.points)
                if column not in self.detail_columns:
                    self.detail_columns.append(column)

    def write(self, path: Path) -> None:
        """Write the CSV atomically: the old file stays until the new one is complete."""
        columns = FIRST + self.detail_columns + LAST
        rows = (self.maximum, *(self.rows[key] for key in sorted(self.rows)))
        write_csv(path, ([row.get(column, "") for column in columns] for row in rows), columns)
