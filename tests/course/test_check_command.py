"""``msdlab check``: the student's view of the checks (table, total, exit status)."""

from __future__ import annotations

import shutil

import pytest

from msdlab.cli import main
from msdlab.course import PROJECT_ROOT
from msdlab.course.report import CheckReport

SOLUTIONS = PROJECT_ROOT / "solutions"


def test_all_checks_of_a_task_pass_on_the_solutions(capsys, tmp_path):
    report = tmp_path / "report.json"
    assert main(["check", "1", "--impl", str(SOLUTIONS), "--report", str(report)]) == 0
    out = capsys.readouterr().out
    assert "check" in out and "points" in out and "result" in out
    assert "task1 particle_count" in out and "total: 9/9 points, 5 of 5 checks passed" in out
    assert "(hidden)" not in out and "what the failing checks saw" not in out
    saved = CheckReport.read(report)
    assert saved.all_passed and saved.tasks() == [1] and not any(c.hidden for c in saved.checks)


def test_templates_fail_with_what_to_do(capsys):
    assert main(["check", "task1", "--impl", "assignments"]) == 1
    out = capsys.readouterr().out
    assert "FAILED  to do: return the number of particles" in out
    assert "NotImplementedError: Task 1: return the number of particles" in out  # details
    assert "total: 0/9 points, 0 of 5 checks passed" in out
    assert "what the failing checks saw:" in out


def test_default_is_the_students_assignments_folder(capsys, tmp_path, monkeypatch):
    (tmp_path / "assignments").mkdir()
    shutil.copy(SOLUTIONS / "task1.py", tmp_path / "assignments" / "task1.py")
    monkeypatch.chdir(tmp_path)
    assert main(["check", "1", "--hidden"]) == 0
    out = capsys.readouterr().out
    assert str(tmp_path / "assignments") in out
    assert "(hidden)" in out and "total: 15/15 points" in out


@pytest.mark.parametrize(
    ("args", "complaint"),
    [
        (["check", "7"], "TASK must be one of 1, 2, 3, 4, 5"),
        (["check", "1", "--impl", "/no/such/folder"], "no folder of task files"),
        (["check", "1", "--checks", "/no/such/checks"], "no checks folder"),
    ],
)
def test_bad_arguments_exit_2(capsys, args, complaint):
    assert main(args) == 2
    assert complaint in capsys.readouterr().err
