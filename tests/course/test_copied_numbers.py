"""Task 1 constants that are another student's own numbers: named in the instructor's
feedback, never in the student's; a crafted task file gives no hint and no crash."""

from __future__ import annotations

import os
from pathlib import Path

import pytest

from msdlab.course import PROJECT_ROOT, own_numbers
from msdlab.course.report import CheckReport
from msdlab.instructor import templates
from msdlab.instructor.intake import copied_numbers
from msdlab.instructor.judging import grading
from msdlab.instructor.outputs import feedback

ROSTER = ("alice", "bob", "carol", "dave", "erin", "frank")


def released(folder: Path, student: str | None) -> Path:
    """``student``'s task1.py as released (the course's defaults for None) in ``folder``."""
    folder.mkdir(parents=True, exist_ok=True)
    own = own_numbers.numbers(student)
    text = templates.render(PROJECT_ROOT / "solutions", own)["task1.py"]
    (folder / "task1.py").write_text(text, encoding="utf-8")
    return folder


def two_with_different_numbers() -> tuple[str, str]:
    pairs = [(a, b) for a in ROSTER for b in ROSTER if a < b]
    return next(
        (a, b)
        for a, b in pairs
        if (own_numbers.numbers(a).bottom, own_numbers.numbers(a).gravity)
        != (own_numbers.numbers(b).bottom, own_numbers.numbers(b).gravity)
    )


def test_own_constants_give_no_hint(tmp_path):
    folder = released(tmp_path / "alice", "alice")
    assert copied_numbers.constants(folder) == (
        own_numbers.numbers("alice").bottom,
        own_numbers.numbers("alice").gravity,
    )
    assert copied_numbers.hint("alice", folder, ROSTER) is None


def test_another_students_constants_are_named(tmp_path):
    mine, theirs = two_with_different_numbers()
    folder = released(tmp_path / mine, theirs)  # mine handed in a copy of theirs
    hint = copied_numbers.hint(mine, folder, ROSTER)
    assert hint is not None and f"the own numbers of {theirs}" in hint
    assert f"not of {mine}" in hint


def test_the_courses_defaults_and_changed_constants_are_said_as_such(tmp_path):
    student = next(s for s in ROSTER if own_numbers.numbers(s) != own_numbers.DEFAULT)
    folder = released(tmp_path / "default", None)
    assert "the course's default numbers" in copied_numbers.hint(student, folder, [student])
    text = (folder / "task1.py").read_text().replace("(-1.0, 1.5, -1.0)", "(-1.0, 9.25, -1.0)")
    (folder / "task1.py").write_text(text)
    assert "were changed" in copied_numbers.hint(student, folder, [student])


@pytest.mark.parametrize(
    "text",
    [
        "ORIGIN = (-1.0, 1.5, -1.0\n",  # does not compile
        "ORIGIN = tuple([-1.0, 1.5, -1.0])\nGRAVITY = (0.0, -0.001, 0.0)\n",  # not a literal
        "ORIGIN = (True, 1.5, False)\nGRAVITY = (0.0, -0.001, 0.0)\n",  # not numbers
        "ORIGIN = (-1.0, 1.5, -1.0)\n",  # no GRAVITY
        "ORIGIN = GRAVITY = (0.0, -0.001, 0.0)\n",  # two targets
        "ORIGIN = (" + "(" * 500 + "1" + ")" * 500 + ", 1.5, 0)\nGRAVITY = (0, -0.001, 0)\n",
        "# " + "x" * 1_100_000 + "\nORIGIN = (-1.0, 1.5, -1.0)\nGRAVITY = (0.0, -0.001, 0.0)\n",
    ],
    ids=["syntax", "call", "bools", "half", "chained", "deep", "huge"],
)
def test_a_crafted_task_file_gives_no_hint(tmp_path, text):
    (tmp_path / "task1.py").write_text(text)
    assert copied_numbers.constants(tmp_path) is None
    assert copied_numbers.hint("alice", tmp_path, ROSTER) is None


def test_a_link_or_bad_bytes_give_no_hint(tmp_path):
    target = released(tmp_path / "elsewhere", "bob")
    (tmp_path / "linked").mkdir()
    os.symlink(target / "task1.py", tmp_path / "linked" / "task1.py")
    assert copied_numbers.constants(tmp_path / "linked") is None
    (tmp_path / "bytes").mkdir()
    (tmp_path / "bytes" / "task1.py").write_bytes(b"ORIGIN = (\xff\xfe)\n")
    assert copied_numbers.constants(tmp_path / "bytes") is None
    assert copied_numbers.constants(tmp_path / "missing") is None


def test_the_hint_reaches_the_instructor_only(tmp_path):
    mine, theirs = two_with_different_numbers()
    folder = released(tmp_path / mine, theirs)
    grade = grading.Grade(mine, CheckReport(implementation="x"), [])
    hint = copied_numbers.hint(mine, folder, set(ROSTER))
    assert hint is not None
    assert f"For you only: {hint}" in feedback.for_instructor(grade, "", hint)
    assert theirs not in feedback.for_student(grade)
