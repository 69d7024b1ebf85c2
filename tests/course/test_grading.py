"""`msdlab grade` against hostile submissions: nothing a submission does raises its grade,
stalls grading, or changes another row; every submission gets a row with the reason."""

from __future__ import annotations

import csv
import os
import shutil
import subprocess
import sys
import textwrap
from pathlib import Path

import pytest

from msdlab.cli import main
from msdlab.course import PROJECT_ROOT
from msdlab.instructor.judging import grading, processes, sandbox
from msdlab.instructor.judging.judges import ForkedJudges
from msdlab.instructor.points import gradebook_db

SOLUTIONS = PROJECT_ROOT / "solutions"
CHECKS = PROJECT_ROOT / "tests" / "tasks"
TASKS_USED = (1, 2, 5)  # enough to show one task's failure leaves the others alone
LIMITS = {"timeout": 240.0, "task_timeout": 10.0, "memory_mb": 1024}


def submission(root: Path, name: str, **edits: str) -> Path:
    """A copy of the reference solutions with code appended to some task files."""
    folder = root / name
    shutil.copytree(SOLUTIONS, folder)
    for file, code in edits.items():
        path = folder / f"{file}.py"
        path.write_text(path.read_text() + "\n" + textwrap.dedent(code))
    return folder


WRONG_COUNT = """
def particle_count(n: int = N) -> int:
    return n * n  # wrong on purpose
"""

TAMPERING = """
import builtins, os, shutil
import numpy as np
import numpy.testing

def attempt(action):  # every attack is tried; refusals are swallowed so the file imports
    try:
        action()
    except Exception:
        pass

np.allclose = lambda *a, **k: True
np.isclose = lambda *a, **k: np.True_
numpy.testing.assert_allclose = lambda *a, **k: None
builtins.abs = lambda x: 0
def patch_pytest():
    import _pytest.runner, pytest
    pytest.approx = lambda *a, **k: True
    _pytest.runner.call_and_report = lambda *a, **k: None
attempt(patch_pytest)
print('{"schema": "msdlab-check-report/1", "checks": []}  89/89 points, all passed')
for target in ("../report.json", "report.json", "/tmp/report.json"):
    attempt(lambda: open(target, "w").write('{"totals": {"earned": 89}}'))
for doomed in ("..", "../checks", os.path.expanduser("~")):
    attempt(lambda: shutil.rmtree(doomed))
"""

ENDLESS = """
def spring_acceleration(x, spacing, stiffness):
    while True:
        pass
"""

GREEDY = """
import numpy as np

def spring_acceleration(x, spacing, stiffness):
    return np.ones(10**11)
"""

STEALING = f"""
def spring_acceleration(x, spacing, stiffness):
    namespace = {{}}
    source = open({str(SOLUTIONS / "task2.py")!r}).read()
    exec(source, namespace)
    return namespace["spring_acceleration"](x, spacing, stiffness)
"""


@pytest.fixture(scope="module")
def graded(tmp_path_factory) -> dict[str, grading.Grade]:
    root = tmp_path_factory.mktemp("class")
    checks = root / "checks"
    checks.mkdir()
    for path in CHECKS.glob("*.py"):  # conftest, helpers (the hidden references) and checks
        if not path.name.startswith("test_") or any(
            path.name.startswith(f"test_task{t}") for t in TASKS_USED
        ):
            shutil.copy(path, checks)
    folders = [
        submission(root, "honest"),
        submission(root, "wrong", task1=WRONG_COUNT),
        submission(root, "tamperer", task1=WRONG_COUNT + TAMPERING),
        submission(root, "endless", task2=ENDLESS),
        submission(root, "greedy", task2=GREEDY),
        submission(root, "exits", task1="import sys\nsys.exit(3)\n"),
        submission(
            root,
            "crashes",
            task5="import os\nDampedVerlet.step = lambda self, x, v, dt, dynamics: os._exit(0)\n",
        ),
        submission(root, "thief", task2=STEALING),
        submission(root, "symlinked"),
    ]
    (folders[-1] / "task2.py").unlink()
    (folders[-1] / "task2.py").symlink_to(SOLUTIONS / "task2.py")
    grades = grading.grade_all(grading.find_submissions(folders), checks, jobs=2, **LIMITS)
    return {grade.submission: grade for grade in grades}


def points(grade: grading.Grade) -> tuple[int, ...]:
    return tuple(grade.points(task) for task in TASKS_USED)


def test_every_submission_is_graded(graded):
    assert all(grade.graded for grade in graded.values()), {
        name: grade.notes for name, grade in graded.items() if not grade.graded
    }
    honest = graded["honest"]
    assert honest.total == honest.report.points > 0 and honest.notes == []


def test_tampering_with_numpy_pytest_files_and_output_changes_nothing(graded):
    """Same wrong answer, with and without tampering: tampering earns nothing, check by check.
    (Its patches of numpy and the builtins stay in the submission's own process, where the
    engine's calls it makes may fail too: it can cost the tamperer, never the grader.)"""
    wrong, tamperer = graded["wrong"], graded["tamperer"]
    assert all(t <= w for t, w in zip(points(tamperer), points(wrong)))
    assert tamperer.points(1) == wrong.points(1) < graded["honest"].points(1)
    failed = {c.nodeid for c in wrong.report.checks if c.outcome != "passed"}
    assert failed <= {c.nodeid for c in tamperer.report.checks if c.outcome != "passed"}
    assert Path.home().exists() and CHECKS.exists()


@pytest.mark.parametrize(
    "name, task, note",
    [
        ("endless", 2, "timed out"),
        ("greedy", 2, "out of memory"),
        ("exits", 1, "sys.exit"),
        ("crashes", 5, "process died"),
    ],
)
def test_a_failure_costs_its_task_only_and_is_explained(graded, name, task, note):
    grade, honest = graded[name], graded["honest"]
    assert grade.points(task) < honest.points(task)
    others = [t for t in TASKS_USED if t != task]
    assert [grade.points(t) for t in others] == [honest.points(t) for t in others]
    assert any(note in text and f"task{task}" in text for text in grade.notes), grade.notes


def test_a_refused_action_at_import_costs_only_that_task(tmp_path):
    rude = submission(tmp_path, "rude", task1="import shutil\nshutil.rmtree('..')\n")
    checks = tmp_path / "checks"
    checks.mkdir()
    for name in ("conftest.py", "test_task1.py", "test_task2.py"):
        shutil.copy(CHECKS / name, checks)
    grade = grading.grade(grading.Submission("rude", rude), checks, **LIMITS)
    assert grade.points(1) == 0 and grade.points(2) > 0
    assert any("task1" in note and "sandbox forbids" in note for note in grade.notes), grade.notes


class DeadServer(ForkedJudges):
    """Judges that cannot be forked (say, the forkserver cannot start in this Python)."""

    def run(self, *args: object) -> tuple[int | None, str]:
        raise OSError("the forkserver could not start")


def test_a_judge_server_that_dies_leaves_the_grading_to_a_fresh_judge(tmp_path):
    checks = tmp_path / "checks"
    checks.mkdir()
    for name in ("conftest.py", "test_task1.py"):
        shutil.copy(CHECKS / name, checks)
    folder = submission(tmp_path, "alice")
    grade = grading.grade(
        grading.Submission("alice", folder), checks, server=DeadServer(), **LIMITS
    )
    assert grade.report is not None and grade.points(1) > 0, grade.notes
    assert not any("server" in note for note in grade.notes), grade.notes


def test_reading_the_solutions_does_not_help(graded):
    assert graded["thief"].points(2) == 0
    messages = " ".join(c.message for c in graded["thief"].report.checks if c.task == 2)
    assert "grading sandbox" in messages or "No such file" in messages or "Permission" in messages


def test_a_symlink_to_the_solutions_is_not_a_submission(graded):
    grade = graded["symlinked"]
    assert grade.points(2) == 0
    assert any("task2.py is not a regular file" in text for text in grade.notes)


def test_grade_command_writes_rows_feedback_and_exit_status(tmp_path, capsys):
    good = submission(tmp_path, "alice")
    empty = tmp_path / "nobody"
    empty.mkdir()
    checks = tmp_path / "checks"
    checks.mkdir()
    shutil.copy(CHECKS / "conftest.py", checks)
    shutil.copy(CHECKS / "test_task1.py", checks)
    out = tmp_path / "grades.csv"
    status = main(["grade", str(good), str(empty), "--out", str(out), "--feedback",
                   str(tmp_path / "feedback"), "--checks", str(checks), "--jobs", "2"])  # fmt: skip
    rows = {row["id"]: row for row in csv.DictReader(out.open())}
    assert status == 1 and set(rows) == {"(max points)", "alice", "nobody"}  # nobody: no files
    assert list(rows["alice"]) == [
        "id",
        "source",
        "task1",
        "task2",
        "task3",
        "task4",
        "task5",
        "points",
        "due",
        "handed_in",
        "handed_in_from",
        "handed_in_control",
        "late",
        "late_penalty",
        "adjustment",
        "total",
        "status",
        "notes",
        "fingerprint",
    ]
    assert rows["alice"]["task1"] == rows["alice"]["total"] == rows["(max points)"]["total"] != "0"
    assert "no task files" in rows["nobody"]["notes"] and rows["nobody"]["total"] == "0"
    assert "points" in (tmp_path / "feedback" / "students" / "alice.md").read_text()
    output = capsys.readouterr()
    assert "[1/1]" in output.err and "graded 1 of 2" in output.out


@pytest.mark.parametrize("starved", [False, True], ids=["given a processor", "starved"])
def test_a_submission_that_outlasts_its_time_limit_still_gets_a_row(tmp_path, monkeypatch, starved):
    """The student's where its processes were given a processor; the grader's, graded again,
    where they waited for one at least half the time (the judge's scheduling figures)."""
    waited = processes.waited_for_processor
    monkeypatch.setattr(processes, "waited_for_processor", lambda pids: 60.0 if starved else
                        waited(pids))  # fmt: skip
    slow = submission(tmp_path, "slow", task1="import time\ntime.sleep(60)\n")
    checks = tmp_path / "checks"
    checks.mkdir()
    shutil.copy(CHECKS / "test_task1.py", checks)
    out = tmp_path / "grades.csv"
    status = main(["grade", str(slow), "--out", str(out), "--checks", str(checks), "--timeout", "8",
                   "--call-timeout", "30", "--retries", "1"])  # fmt: skip
    row = {row["id"]: row for row in csv.DictReader(out.open())}["slow"]
    assert row["total"] == ("" if starved else "0")  # the grader's failure has no points
    assert (row["status"] == "grader failed") == starved
    assert status == (2 if starved else 1)
    assert ("grader error" in row["notes"]) == starved
    assert ("timed out after 8 s" if not starved else "waited for a processor") in row["notes"]
    assert gradebook_db.read_class(out)[0].attempts == (2 if starved else 1)


@pytest.mark.skipif(os.geteuid() != 0, reason="sandbox user ids are used only when grading as root")
def test_concurrent_grading_runs_never_share_a_sandbox_user():
    with grading.reserved_uids(2) as first, grading.reserved_uids(3) as second:
        assert len(set(first) | set(second)) == 5
    with grading.reserved_uids(1) as again:
        assert again[0] == min(first + second)  # released when the runs end


@pytest.mark.parametrize("isolation", ["namespace", "process"])
def test_grading_from_a_folder_holding_one_named_msdlab_grades_normally(tmp_path, isolation):
    """The judges import the installed msdlab, not the folder ``msdlab`` (an empty one here;
    a clone of the course in the instructor's journey test) where grading runs."""
    if isolation == "namespace" and sandbox.isolation_problem() is not None:
        pytest.skip(sandbox.isolation_problem())
    (tmp_path / "msdlab").mkdir()
    checks = tmp_path / "checks"
    checks.mkdir()
    for name in ("conftest.py", "test_task1.py"):
        shutil.copy(CHECKS / name, checks)
    alice = tmp_path / "class" / "alice"
    alice.mkdir(parents=True)
    shutil.copy(SOLUTIONS / "task1.py", alice)
    command = [str(Path(sys.executable).with_name("msdlab")), "grade", "class/alice", "--out",
               "grades.csv", "--checks", str(checks), "--isolation", isolation]  # fmt: skip
    result = subprocess.run(command, cwd=tmp_path, capture_output=True, text=True, timeout=300)
    assert result.returncode == 0, result.stderr
    rows = {row["id"]: row for row in csv.DictReader((tmp_path / "grades.csv").open())}
    assert rows["alice"]["task1"] == rows["(max points)"]["task1"] != "0", rows["alice"]["notes"]
