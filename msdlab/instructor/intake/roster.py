"""The roster: which submission is whose, the one place a student's id comes from.

A roster is a CSV file whose first line names its columns (the same rule for
``msdlab grade``, ``msdlab similarity`` and ``msdlab export``): ``id`` (the student's
roster id, which their own numbers follow) and, for grading, ``folder`` (the folder or
zip file handed in, relative to the roster's folder; ``submission``, ``path`` or ``zip``
name it too). Other columns (``name``, ``email``, ``sis_id`` …) are kept for the export.
Blank lines and lines whose id starts with ``#`` are skipped.
"""

from __future__ import annotations

import csv
import re
from dataclasses import dataclass
from pathlib import Path

FOLDER_COLUMNS = ("folder", "submission", "path", "zip", "folder-or-zip")
EXAMPLE = "id,folder\nalice,alice/assignments\ncarol,carol.zip"


@dataclass(frozen=True)
class Student:
    """One roster line: the id as written, its folder or zip (None: not given), the line."""

    id: str
    folder: Path | None
    line: int


def read(path: Path) -> list[Student]:
    """The roster's students, in its order (see the module); clear errors for a file that
    does not name its columns."""
    path = Path(path)
    if not path.is_file():
        raise FileNotFoundError(f"no roster file at {path}")
    with path.open(newline="", encoding="utf-8-sig") as handle:
        reader = csv.reader(handle)
        header = [_column(cell) for cell in next(reader, [])]
        if "id" not in header:
            raise ValueError(
                f"{path}: the first line must name the columns, one of them 'id' (and "
                f"'folder' for grading), e.g.\n{EXAMPLE}"
            )
        where = next((header.index(c) for c in FOLDER_COLUMNS if c in header), None)
        students = []
        for line, row in enumerate(reader, start=2):
            cells = dict(zip(header, row))
            identifier = cells.get("id", "")
            if not identifier.strip() and any(cell.strip() for cell in row):
                raise ValueError(
                    f"roster {path}, line {line}: '{','.join(row)}' has no id; give each line "
                    "the student's id in the 'id' column"
                )
            if not identifier.strip() or identifier.strip().startswith("#"):
                continue
            folder = row[where].strip() if where is not None and where < len(row) else ""
            place = (path.parent / folder) if folder else None
            students.append(Student(identifier, place, line))
    return students


def _column(cell: str) -> str:
    """A column's name as the rule reads it (case, spaces and ``_`` ignored)."""
    return re.sub(r"[\s_]+", "-", cell.strip().lower())
