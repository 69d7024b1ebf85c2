"""Manual changes to grades that last: a CSV beside the grades file, applied after every run.

``grades.csv`` has its changes in ``grades.adjustments.csv``, one per line, with a header::

    id,task,change,reason,note
    alice,2,=4,checked by hand: the sign convention was stated in her notebook,
    bob,,+1,extra credit for the report,
    carol,3,=0,"task 3 is the same code as another student's, names changed",copied from dave

- ``task``: ``1`` ... ``5`` (or ``task2``) changes that task's points, before any late
  penalty; empty or ``total`` changes the total, after the late penalty.
- ``change``: ``+1`` or ``-2.5`` adds to the points; ``=4`` sets them (an override).
- ``reason``: required; the student's and the instructor's feedback both show it.
- ``note`` (optional column): private; only the instructor's feedback shows it, never the
  student's.

The whole file is checked before anything is graded or exported (`problems`): a line with
more fields than the header (an unquoted comma), a line repeated, two settings of one
student's task, an addition a later setting overrides, a change beyond what the task or
the total is worth, an id that is a lookalike of a student's are refused with the line and
the fix; an id no submission has is warned about. The grades file itself is rewritten by
every run; this file is only read, so no run loses a manual decision.
"""

from __future__ import annotations

import re
from collections.abc import Collection, Mapping
from dataclasses import dataclass, field
from fractions import Fraction
from pathlib import Path

from ...course import TASKS
from ..outputs.csv_files import read_table, too_many_fields
from .late import format_points
from .problems import Problem, raise_refused

COLUMNS = ("id", "task", "change", "reason")
PRIVATE = "note"
"""The optional column of the instructor's private note (never shown to the student)."""
_CHANGE = re.compile(r"^\s*([=+-])\s*(\d+(?:\.\d+)?)\s*$")


@dataclass(frozen=True)
class Change:
    """One manual change: to ``task`` (None: the total), setting or adding ``value`` points."""

    id: str
    task: int | None
    value: Fraction
    sets: bool
    reason: str
    note: str = ""
    line: int = field(default=0, compare=False)  # in the adjustments file

    @property
    def column(self) -> str:
        """The grades' column it changes (``task2``, ``total``)."""
        return "total" if self.task is None else f"task{self.task}"

    def apply(self, points: Fraction) -> Fraction:
        """The points after this change."""
        return self.value if self.sets else points + self.value

    def __str__(self) -> str:
        """The change as the student reads it (the private note left out)."""
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
    """The changes in ``path`` by student id, in the file's order (none if there is no
    file); an `InstructorFileError` naming every mistake `parse` and `problems` find."""
    changes, found = parse(path)
    raise_refused(found + problems(changes, str(path)))
    return by_student(changes)


def by_student(changes: list[Change]) -> dict[str, list[Change]]:
    """``changes`` by student id, each student's in the file's order."""
    grouped: dict[str, list[Change]] = {}
    for change in changes:
        grouped.setdefault(change.id, []).append(change)
    return grouped


def parse(path: Path) -> tuple[list[Change], list[Problem]]:
    """The changes written in ``path`` (none if there is no file) and the mistakes of its
    lines, each line on its own."""
    path = Path(path)
    if not path.is_file():
        return [], []
    columns, lines = read_table(path)
    unknown = [c for c in columns if c not in (*COLUMNS, PRIVATE)]
    if columns[:4] != list(COLUMNS) or unknown:
        header = ",".join((*COLUMNS, PRIVATE))
        return [], [
            Problem(
                f"{path}, line 1",
                f"the first line must be '{header}' (the note optional), not '{','.join(columns)}'",
                "a private note goes in the column 'note'",
            )
        ]
    changes, found = [], []
    for line in lines:
        where = f"{path}, line {line.number}"
        try:
            if line.extra:
                found.append(too_many_fields(where, line.extra))
            elif line.raw.get(PRIVATE, "")[:1].isspace():
                found.append(
                    too_many_fields(
                        where,
                        [line.cells[PRIVATE]],
                        "a note starting with a space, the end of the reason?",
                    )
                )
            else:
                changes.append(_change(line.cells, line.number))
        except ValueError as error:
            found.append(Problem(where, str(error)))
    return changes, found


def _change(cells: dict[str, str], number: int) -> Change:
    if not cells.get("id"):
        raise ValueError("no student id; write the id first, as in the grades")
    task_text = cells.get("task", "").lower().removeprefix("task").strip()
    if task_text in ("", "total"):
        task = None
    elif task_text.isdigit() and int(task_text) in TASKS:
        task = int(task_text)
    else:
        raise ValueError(f"task {cells['task']!r} is not one of {TASKS} or 'total'")
    match = _CHANGE.match(cells.get("change", ""))
    if match is None:
        raise ValueError(
            f"change {cells.get('change', '')!r} must be like +1, -2.5 or =4 (sets it)"
        )
    sign, amount = match.groups()
    value = Fraction(amount) * (-1 if sign == "-" else 1)
    if not cells.get("reason"):
        raise ValueError("give the reason for the change (the student will read it)")
    return Change(
        cells["id"], task, value, sign == "=", cells["reason"], cells.get(PRIVATE, ""), number
    )


def problems(changes: list[Change], where: str) -> list[Problem]:
    """The mistakes of the changes read from the file ``where`` taken together: repeated
    lines, settings that override."""
    return [problem for problem in _repeated(changes, where) if problem is not None]


def against_class(
    changes: list[Change],
    where: str,
    maximum: Mapping[str, Fraction] | None,
    known: Collection[str] | None,
) -> list[Problem]:
    """The mistakes of the changes read from the file ``where`` that only the class shows:
    changes beyond the points of ``maximum`` (column -> points), ids that are not ``known``
    (refused if a lookalike of one, else warned); None: not checked."""
    found = [_beyond(change, maximum, where) for change in changes] if maximum else []
    if known is not None:
        found += [_unknown(change, known, where) for change in changes]
    return [problem for problem in found if problem is not None]


def _repeated(changes: list[Change], where: str) -> list[Problem | None]:
    """Lines repeated exactly, and changes a later setting of the same points overrides."""
    found: list[Problem | None] = []
    seen: dict[tuple, int] = {}
    for number, change in enumerate(changes):
        at = f"{where}, line {change.line}"
        key = (change.id, change.task, change.value, change.sets, change.reason)
        if key in seen:
            found.append(
                Problem(
                    at,
                    f"repeats line {seen[key]} (the same change and reason: it would count twice)",
                    "delete one; to add twice, write the sum once",
                )
            )
            continue
        seen[key] = change.line
        later = next(
            (
                c
                for c in changes[number + 1 :]
                if c.sets
                and c.id == change.id
                and c.column == change.column
                and c.line != change.line
                and (c.value, c.reason) != (change.value, change.reason)
            ),
            None,
        )
        if later is not None:
            found.append(
                Problem(
                    at,
                    f"line {later.line} sets {change.id}'s {change.column} "
                    "later, so this change would count for nothing",
                    "keep one, or put the setting (=) first",
                )
            )
    return found


def _beyond(change: Change, maximum: Mapping[str, Fraction], where: str) -> Problem | None:
    """A change to more points than its column is worth (``=900`` of 15), or by more."""
    worth = maximum.get(change.column)
    if worth is None or (0 <= change.value <= worth if change.sets else abs(change.value) <= worth):
        return None
    what = f"{change.column} is worth {format_points(worth)} points"
    wrong = (
        f"sets it to {format_points(change.value)}"
        if change.sets
        else f"changes it by {format_points(change.value)}"
    )
    return Problem(
        f"{where}, line {change.line}",
        f"{what}; this line {wrong}",
        f"write a change within 0 ... {format_points(worth)}",
    )


def _unknown(change: Change, known: Collection[str], where: str) -> Problem | None:
    """An id no submission has: a lookalike of one (case, spaces) is refused, any other is
    warned about (a student not graded yet)."""
    if change.id in known:
        return None
    plain = plain_id(change.id)
    alike = sorted(k for k in known if plain_id(k) == plain)
    at = f"{where}, line {change.line}"
    if alike:
        return Problem(
            at,
            f"no submission has the id {change.id!r}",
            f"did you mean {alike[0]!r}? write the id exactly",
        )
    return Problem(
        at,
        f"no submission has the id {change.id!r}: the change waits for one",
        "check the id against the grades",
        refused=False,
    )


def plain_id(identifier: str) -> str:
    """An id as a lookalike reads it: case and runs of spaces ignored."""
    return " ".join(identifier.split()).casefold()


def private_notes(changes: Mapping[str, list[Change]]) -> dict[str, list[str]]:
    """Each student's private notes, as the instructor's feedback lists them."""
    return {
        identifier: [
            f"- private note on “{change}”: {change.note}" for change in made if change.note
        ]
        for identifier, made in changes.items()
        if any(change.note for change in made)
    }
