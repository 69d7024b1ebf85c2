"""``msdlab handin``: the zip a student hands in holds exactly the task files the grader
reads, says what it holds and what is still the template's, and the grader takes it as it
is (through the real intake)."""

from __future__ import annotations

import csv
import shutil
import zipfile
from pathlib import Path

from msdlab.cli import main
from msdlab.course import PROJECT_ROOT

SOLUTIONS = PROJECT_ROOT / "solutions"
TEMPLATES = PROJECT_ROOT / "assignments"
CHECKS = PROJECT_ROOT / "tests" / "tasks"


def course_folder(tmp_path: Path) -> Path:
    """A student's course folder: task 1 answered, the other tasks' templates, and what else
    such a folder holds (a virtual environment, notebooks, outputs, caches, notes)."""
    course = tmp_path / "course"
    shutil.copytree(TEMPLATES, course / "assignments", ignore=shutil.ignore_patterns("*.json"))
    shutil.copy(SOLUTIONS / "task1.py", course / "assignments" / "task1.py")
    (course / "assignments" / "task5.py").unlink()
    (course / "assignments" / "notes.txt").write_text("my notes\n")
    (course / "assignments" / "__pycache__").mkdir(exist_ok=True)
    (course / "assignments" / "__pycache__" / "task1.cpython-311.pyc").write_bytes(b"\0" * 64)
    for folder in (".venv/lib", "notebooks", "msdlab-output"):
        (course / folder).mkdir(parents=True)
        (course / folder / "big.bin").write_bytes(b"\0" * 100_000)
    return course


def test_the_zip_holds_exactly_the_task_files_and_says_what_is_left(tmp_path, monkeypatch, capsys):
    course = course_folder(tmp_path)
    monkeypatch.chdir(course / "notebooks")  # anywhere in the course folder
    assert main(["handin"]) == 0
    out = capsys.readouterr().out
    with zipfile.ZipFile(course / "handin.zip") as bundle:
        names = sorted(bundle.namelist())
        assert names == [f"assignments/task{n}.py" for n in (1, 2, 3, 4)]
        assert bundle.read("assignments/task1.py") == (SOLUTIONS / "task1.py").read_bytes()
    assert (course / "handin.zip").stat().st_size < 30_000
    assert f"wrote {course / 'handin.zip'}" in out
    task1, task2 = out.index("assignments/task1.py"), out.index("assignments/task2.py")
    assert "still the template's" not in out[task1:task2]  # task 1 is answered
    assert "warning: 1 part still the template's, to write (line " in out[task2:]
    assert "task5.py missing from" in out and "upload handin.zip" in out


def test_the_grader_takes_the_zip_as_it_is(tmp_path, monkeypatch, capsys):
    """The zip graded by ``msdlab grade`` (its intake, its sandbox) gets the points of the
    task files it holds: task 1 in full, the templates' tasks none."""
    course = course_folder(tmp_path)
    monkeypatch.chdir(course)
    assert main(["handin", "--out", str(tmp_path / "handed-in" / "alice.zip")]) == 0
    checks = tmp_path / "checks"
    checks.mkdir()
    for name in ("conftest.py", "test_task1.py", "test_task2.py"):
        shutil.copy(CHECKS / name, checks)
    out = tmp_path / "grades.csv"
    given = [str(tmp_path / "handed-in" / "alice.zip"), "--checks", str(checks), "--out", str(out)]
    assert main(["grade", *given, "--call-timeout", "20", "--jobs", "1"]) == 0
    capsys.readouterr()
    (row,) = [r for r in csv.DictReader(out.open(encoding="utf-8")) if r["id"] == "alice"]
    assert row["task1"] == "9" and row["task2"] == "0", row
