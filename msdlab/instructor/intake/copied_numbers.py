"""Task 1 constants that are not the student's own numbers: a hint for the instructor.

Where the course gives each student their own numbers (`course.own_numbers`), a task 1
file whose ``ORIGIN`` and ``GRAVITY`` hold another student's numbers was most likely
copied from that student's release, and one holding the course's defaults from the
course's own templates. The grader only sees that answers do not fit the student's
numbers; `hint` says whose numbers they are, for the instructor's eyes only (the
student's feedback never names another student). The file is read as text: its
constants must be plain number tuples, nothing of it is run.
"""

from __future__ import annotations

import ast
from collections.abc import Iterable
from pathlib import Path

from ...course import own_numbers

TASK_FILE = "task1.py"
MAX_BYTES = 1_000_000  # a larger task file is left to the grader, which refuses it


def constants(folder: Path) -> tuple[float, float] | None:
    """(ORIGIN[1], GRAVITY[1]) as written in ``folder``'s task1.py; None where the file is
    missing, too large, not Python, or does not assign both as tuples of three numbers."""
    path = Path(folder) / TASK_FILE
    try:
        if path.is_symlink() or not path.is_file() or path.stat().st_size > MAX_BYTES:
            return None
        tree = ast.parse(path.read_bytes())
    except (OSError, SyntaxError, ValueError):
        return None
    found: dict[str, float] = {}
    for node in tree.body:
        if not (isinstance(node, ast.Assign) and len(node.targets) == 1):
            continue
        target = node.targets[0]
        if isinstance(target, ast.Name) and target.id in ("ORIGIN", "GRAVITY"):
            value = _triple(node.value)
            if value is not None:
                found[target.id] = value[1]
    if set(found) != {"ORIGIN", "GRAVITY"}:
        return None
    return found["ORIGIN"], found["GRAVITY"]


def hint(student: str, folder: Path, roster: Iterable[str]) -> str | None:
    """What the instructor should know about ``student``'s task 1 constants (in ``folder``)
    when they are not their own numbers: whose they are among ``roster``, or the course's
    defaults; None where they are the student's own or cannot be read."""
    found = constants(folder)
    own = own_numbers.numbers(student)
    if found is None or found == (own.bottom, own.gravity):
        return None
    written = f"ORIGIN[1] = {found[0]!r}, GRAVITY[1] = {found[1]!r}"
    theirs = f"{student}'s own are {own.bottom!r} and {own.gravity!r}"
    owners = sorted(
        other
        for other in set(roster) - {student}
        if other.strip()
        and (own_numbers.numbers(other).bottom, own_numbers.numbers(other).gravity) == found
    )
    if owners:
        return (
            f"task 1's constants ({written}) are the own numbers of {', '.join(owners)}, not "
            f"of {student} ({theirs}): copied from {'their' if len(owners) > 1 else 'that'} "
            "release?"
        )
    default = own_numbers.DEFAULT
    if found == (default.bottom, default.gravity):
        return (
            f"task 1's constants ({written}) are the course's default numbers, not {student}'s "
            f"own ({theirs}): a template from the course's checkout, not their release?"
        )
    return f"task 1's constants ({written}) were changed: {theirs}"


def _triple(node: ast.expr) -> tuple[float, float, float] | None:
    """The value of a literal tuple of three numbers; None for anything else."""
    try:
        value = ast.literal_eval(node)
    except (ValueError, TypeError, SyntaxError, MemoryError, RecursionError):
        return None
    if not (isinstance(value, tuple) and len(value) == 3):
        return None
    if not all(isinstance(x, (int, float)) and not isinstance(x, bool) for x in value):
        return None
    return tuple(float(x) for x in value)  # type: ignore[return-value]
