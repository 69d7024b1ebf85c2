"""Each student's own numbers: template parameters derived from the student's roster id.

Where a task's answer is a number one student could hand another (task 1: the step in
which the bottom layer reaches the floor, its height; task 4: the springs of the grid
whose cost is measured), the course may give every student their own parameters. They
are derived from the roster id alone (SHA-256 of the id as the seed), so the release,
the student's ``msdlab check`` and the grader agree without sharing a file:

- tasks 1 and 2: the height y0 of the bottom layer (``ORIGIN[1]``, 1.5 by default) and
  the template's acceleration g (``GRAVITY[1]``, -0.001), in both task files (task 2 is
  the template with springs); task 5's check of the template's trajectory drops the grid
  from the same height;
- task 4: the grid size n of the cost measurement (6 by default).

The numbers a student reads (the task files' docstrings, the notebooks' text) are written
as markers ``{{ name }}`` in the solutions and the notebooks' sources and filled in from
the same `Numbers` (`filled`, `shown`): the defaults in the course's checkout, the
student's own in their release.

Off by default: the switch is ``"own_numbers": true`` in the course's settings file
``course.json`` (at the course root), read by ``msdlab release`` and ``msdlab grade``.
A release for one student writes their id into ``assignments/student.json``; the checks
take the id from ``--student ID`` (the grader), else from that file, else use the
defaults.
"""

from __future__ import annotations

import hashlib
import json
import math
import re
from dataclasses import dataclass
from pathlib import Path

SETTINGS_FILE = "course.json"
STUDENT_FILE = "student.json"
HEIGHTS = tuple(round(1.2 + 0.1 * i, 1) for i in range(9))  # y0: 1.2 ... 2.0
ACCELERATIONS = (-0.0008, -0.0009, -0.001, -0.0011, -0.0012)  # g
COST_SIZES = (5, 6, 7, 8)  # n of task 4's step_cost check
DT = 0.1  # task 1: the template's time step, the same for everyone
MARKER = re.compile(r"\{\{ *(\w+) *\}\}")
"""A number to fill in, ``{{ name }}``: one of `shown`'s names."""


@dataclass(frozen=True)
class Numbers:
    """One student's parameters (the defaults are the template's own)."""

    bottom: float = 1.5  # task 1: height of the bottom layer, ORIGIN[1]
    gravity: float = -0.001  # task 1: the template's acceleration, GRAVITY[1]
    cost_size: int = 6  # task 4: particles per edge of the grid step_cost is checked on


DEFAULT = Numbers()


def numbers(student: str | None) -> Numbers:
    """The numbers of ``student`` (a roster id); the defaults for None."""
    if student is None:
        return DEFAULT
    if not student.strip():
        raise ValueError("a student id for their own numbers must not be empty")
    seed = int.from_bytes(hashlib.sha256(student.strip().encode("utf-8")).digest()[:8], "big")
    return Numbers(
        HEIGHTS[seed % len(HEIGHTS)],
        ACCELERATIONS[seed // len(HEIGHTS) % len(ACCELERATIONS)],
        COST_SIZES[seed // (len(HEIGHTS) * len(ACCELERATIONS)) % len(COST_SIZES)],
    )


def course_of(checks: Path) -> Path:
    """The course folder whose settings apply to the checks in ``checks`` (``tests/tasks``)."""
    return Path(checks).resolve().parent.parent


def enabled(course: Path) -> bool:
    """Whether the course at ``course`` gives each student their own numbers (its settings)."""
    path = Path(course) / SETTINGS_FILE
    if not path.is_file():
        return False
    try:
        settings = json.loads(path.read_text(encoding="utf-8"))
    except ValueError as error:
        raise ValueError(f"{path} is not valid JSON ({error}); fix or remove it") from None
    switch = settings.get("own_numbers", False) if isinstance(settings, dict) else None
    if not isinstance(switch, bool):
        raise ValueError(f'{path}: "own_numbers" must be true or false, got {switch!r}')
    return switch


def shown(own: Numbers) -> dict[str, str]:
    """The numbers a student reads, by marker name: ``y0`` (the bottom layer's height),
    ``g`` (the template's acceleration), ``fall_time`` (the time t at which the exact free
    fall y0 + ½ g t² reaches the floor, in the template's time units: a time, not a step,
    so that no step a check rejects is read as the answer)."""
    return {
        "y0": repr(own.bottom),
        "g": repr(own.gravity),
        "fall_time": f"{math.sqrt(2.0 * own.bottom / -own.gravity):.1f}",
    }


def filled(text: str, own: Numbers, where: str = "the text") -> str:
    """``text`` with every marker ``{{ name }}`` replaced by ``own``'s number of that name."""
    numbers = shown(own)
    unknown = sorted({name for name in MARKER.findall(text) if name not in numbers})
    if unknown:
        raise ValueError(
            f"{where}: no number named {', '.join(unknown)} to fill in; the markers "
            f"{{{{ name }}}} take one of {', '.join(numbers)}"
        )
    return MARKER.sub(lambda match: numbers[match[1]], text)


OWN_CONSTANTS = (1, 2)
"""The tasks whose files hold the template's ``ORIGIN`` and ``GRAVITY``, given as own numbers."""


def personalised(task: int, source: str, own: Numbers) -> str:
    """The template (or solution) text of ``task`` with ``own`` numbers in its constants
    and in its markers (`filled`)."""
    source = filled(source, own, f"task{task}.py")
    if task not in OWN_CONSTANTS:
        return source
    replaced = {
        "ORIGIN": f"(-1.0, {own.bottom!r}, -1.0)",
        "GRAVITY": f"(0.0, {own.gravity!r}, 0.0)",
    }
    for name, value in replaced.items():
        source, count = re.subn(rf"^{name} = \([^)\n]*\)", f"{name} = {value}", source, flags=re.M)
        if count != 1:
            raise ValueError(f"task{task}.py: no single line '{name} = (...)' to give own numbers")
    return source


def write_student(folder: Path, student: str) -> Path:
    """Write ``student`` as the owner of the task files in ``folder`` (for ``msdlab check``)."""
    path = Path(folder) / STUDENT_FILE
    path.write_text(json.dumps({"id": student}) + "\n", encoding="utf-8")
    return path


def student_of(folder: Path) -> str | None:
    """The student whose task files ``folder`` holds, from its ``student.json``; else None."""
    path = Path(folder) / STUDENT_FILE
    if not path.is_file():
        return None
    try:
        student = json.loads(path.read_text(encoding="utf-8")).get("id")
    except (ValueError, AttributeError):
        student = None
    if not isinstance(student, str) or not student.strip():
        raise ValueError(f'{path} should hold {{"id": "your roster id"}}; ask for a new release')
    return student


def announced(folder: Path) -> str | None:
    """The line that tells a student the checks of the task files in ``folder`` use their own
    numbers (from its ``student.json``), and which; None where they use the course's."""
    student = student_of(folder)
    if student is None:
        return None
    own = numbers(student)
    return (
        f"your own numbers (student {student}): tasks 1 and 2 y0 = ORIGIN[1] = {own.bottom!r} "
        f"and g = GRAVITY[1] = {own.gravity!r}; task 4's step_cost is checked on a "
        f"{own.cost_size}×{own.cost_size}×{own.cost_size} grid"
    )
