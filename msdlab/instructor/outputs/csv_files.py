"""Every CSV file the course writes or reads: formula-safe cells that read back exactly.

A spreadsheet takes a cell starting with ``=``, ``+``, ``-``, ``@`` (or their full-width
forms, a tab or a carriage return) for a formula. `neutralised` puts a ``'`` before such a
cell, and before a cell that itself starts with ``'``; `restored` takes one leading ``'``
away. So every text reads back as it was written (``'=x`` is written ``''=x`` and reads
``'=x``), and no cell a student controls (an id, a folder name) runs in a spreadsheet. A
number (``-2.5``) is written as it is.

The instructor's own files (adjustments, extensions) are read by `read_table`, which keeps
each line's number and the fields beyond the header's columns (an unquoted comma), so that
their checks can name both.
"""

from __future__ import annotations

import csv
import io
import re
from collections.abc import Iterable, Sequence
from dataclasses import dataclass, field
from pathlib import Path

from ..rules.problems import Problem
from . import output_files

FORMULA_STARTS = ("=", "+", "-", "@", "\t", "\r", "\uff1d", "\uff0b", "\uff0d", "\uff20")
"""A cell starting with one of these is a formula to a spreadsheet (full-width forms too)."""
QUOTE = "'"
NUMBER = re.compile(r"-?\d+(\.\d+)?")


def neutralised(value: object) -> str:
    """``value`` as a CSV cell no spreadsheet takes for a formula (a number stays a number);
    `restored` gives it back exactly."""
    text = str(value)
    if NUMBER.fullmatch(text):
        return text
    return QUOTE + text if text.startswith((*FORMULA_STARTS, QUOTE)) else text


def restored(text: str) -> str:
    """The value of a cell `neutralised` made."""
    return text.removeprefix(QUOTE)


def csv_text(lines: Iterable[Sequence[object]], header: Sequence[str] | None = None) -> str:
    """The CSV text of ``lines`` (after an optional ``header``), every cell `neutralised`."""
    text = io.StringIO()
    writer = csv.writer(text)  # lines end in \r\n (RFC 4180): a \r in a cell is quoted
    if header is not None:
        writer.writerow([neutralised(name) for name in header])
    writer.writerows([neutralised(cell) for cell in line] for line in lines)
    return text.getvalue()


def write_csv(path: Path, lines: Iterable[Sequence[object]], header: Sequence[str] | None = None
              ) -> None:  # fmt: skip
    """Write ``lines`` as a UTF-8 CSV file at ``path`` (`csv_text`), atomically: a crash
    leaves the old file or the whole new one; a path that is a link is refused."""
    output_files.write_text(path, csv_text(lines, header), "CSV file", durable=True)


def read_csv(path: Path) -> list[list[str]]:
    """The lines of a CSV file `write_csv` wrote, every cell `restored`."""
    with Path(path).open(newline="", encoding="utf-8-sig") as handle:
        return [[restored(cell) for cell in line] for line in csv.reader(handle)]


@dataclass
class Line:
    """One line of an instructor's CSV file: its number in the file (the first line is 1),
    its cells by column (names in lower case, values stripped) and the fields beyond the
    header's columns."""

    number: int
    cells: dict[str, str]
    extra: list[str] = field(default_factory=list)
    raw: dict[str, str] = field(default_factory=dict)  # the cells as written, spaces kept


def read_table(path: Path) -> tuple[list[str], list[Line]]:
    """The column names (lower case) of the CSV file at ``path`` and its lines below them,
    blank lines left out."""
    with Path(path).open(newline="", encoding="utf-8-sig") as handle:
        reader = csv.reader(handle)
        columns = [name.strip().lower() for name in next(reader, [])]
        lines = []
        start = reader.line_num + 1
        for fields in reader:
            cells = [value.strip() for value in fields]
            if any(cells):
                named, raw = dict(zip(columns, cells)), dict(zip(columns, fields))
                lines.append(Line(start, named, [c for c in cells[len(columns) :] if c], raw))
            start = reader.line_num + 1
    return columns, lines


def too_many_fields(where: str, extra: list[str], seen: str = "") -> Problem:
    """The problem of a line with fields beyond the header's columns (``seen``: how else a
    cut field shows)."""
    what = seen or "more fields than the first line names columns"
    return Problem(
        where,
        f"{what} (left over: {', '.join(extra)})",
        'a comma inside a reason or note must be in double quotes: alice,2,+1,"checked, fine"',
    )
