"""Manual changes to grades that last: a CSV beside the grades file, applied after every run.

``grades.csv`` has its changes in ``grades.adjustments.csv``, one per line, with a header::

    id,task,change,reason
    alice,2,=4,checked by hand: the sign convention was stated in her notebook
    bob,,+1,extra credit for the report

- ``task``: ``1`` ... ``5`` (or ``task2``) changes that task's points, before any late
  penalty; empty or ``total`` changes the total, after the late penalty.
- ``change``: ``+1`` or ``-2.5`` adds to the points; ``=4`` sets them (an override).
- ``reason``: required; the student's and the instructor's feedback both show it.

The grades file itself is rewritten by every run; this file is only read, so no run
loses a manual decision.
"""

from __future__ import annotations

import csv
import re
from dataclasses import dataclass
from fractions import Fraction
from pathlib import Path

from ..course import TASKS
from .late import format_points

COLUMNS = ("id", "task", "change", "reason")
_CHANGE = re.compile(r"^\s*([=+-])\s*(\d+(?:\.\d+)?)\s*$")


@dataclass(frozen=True)
class Change:
    """One manual change: to ``task`` (None: the total), setting or adding ``value`` points."""

    id: str
    task: int | None
    value: Fraction
    sets: bool
    reason: str

    def apply(self, points: Fraction) -> Fraction:
        """The points after this change."""
        return self.value if self.sets else points + self.value

    def __str__(self) -> str:
        what = f"task {self.task}" if self.task is not None else "total"
        unit = "point" if abs(self.value) == 1 else "points"
        if self.sets:
            return f"{what} set to {format_points(self.value)} {unit}: {self.reason}"
        sign = "+" if self.value >= 0 else "−"
        return f"{what} {sign}{format_points(abs(self.value))} {unit}: {self.reason}"


def beside(grades: Path) -> Path:
    """The adjustments file of the grades file ``grades`` (grades.csv -> grades.adjustments.csv)."""
    grades = Path(grades)
    return grades.with_name(f"{grades.stem}.adjustments.csv")


def read(path: Path) -> dict[str, list[Change]]:
    """The changes in ``path`` by student id, in the file's order (none if there is no file)."""
    path = Path(path)
    changes: dict[str, list[Change]] = {}
    if not path.is_file():
        return changes
    with path.open(newline="", encoding="utf-8-sig") as handle:
        reader = csv.DictReader(handle)
        if [c.strip().lower() for c in reader.fieldnames or []][:4] != list(COLUMNS):
            raise ValueError(f"{path}: the first line must be '{','.join(COLUMNS)}'")
        for number, row in enumerate(reader, start=2):
            cells = {k.strip().lower(): (v or "").strip() for k, v in row.items() if k}
            if not any(cells.values()):
                continue
            change = _change(cells, f"{path}, line {number}")
            changes.setdefault(change.id, []).append(change)
    return changes


def _change(cells: dict[str, str], where: str) -> Change:
    if not cells.get("id"):
        raise ValueError(f"{where}: no student id")
    task_text = cells.get("task", "").lower().removeprefix("task").strip()
    if task_text in ("", "total"):
        task = None
    elif task_text.isdigit() and int(task_text) in TASKS:
        task = int(task_text)
    else:
        raise ValueError(f"{where}: task {cells['task']!r} is not one of {TASKS} or 'total'")
    match = _CHANGE.match(cells.get("change", ""))
    if match is None:
        raise ValueError(
            f"{where}: change {cells.get('change', '')!r} must be like +1, -2.5 or =4 (sets it)"
        )
    sign, number = match.groups()
    value = Fraction(number) * (-1 if sign == "-" else 1)
    if not cells.get("reason"):
        raise ValueError(f"{where}: give the reason for the change (the student will read it)")
    return Change(cells["id"], task, value, sign == "=", cells["reason"])
