"""The pytest plugin: choosing the implementation, markers and points, the JSON report."""

from __future__ import annotations

import json
import os
import re
import subprocess
import sys
from pathlib import Path

import pytest

CHECK = """
import pytest

from msdlab.course.feedback import expect

pytestmark = pytest.mark.task1


@pytest.mark.points(2)
def test_answer(task1):
    got = task1.answer()
    expect(got == 42, saw=f"the answer is {got}", cause="counting from 0")


@pytest.mark.points(1)
@pytest.mark.hidden
def test_hidden_answer(task1):
    assert task1.answer() > 0
"""


@pytest.fixture
def course(tmp_path: Path) -> Path:
    """A tiny course: solutions/, assignments/, another folder mine/, and a checks folder."""
    for folder, body in (
        ("solutions", "return 42"),
        ("assignments", 'raise NotImplementedError("Task 1: return 42")'),
        ("mine", "return 41"),
    ):
        (tmp_path / folder).mkdir()
        (tmp_path / folder / "task1.py").write_text(f"def answer():\n    {body}\n")
    (tmp_path / "checks").mkdir()
    (tmp_path / "checks" / "test_demo.py").write_text(CHECK)
    (tmp_path / "checks" / "test_other.py").write_text("def test_not_graded():\n    pass\n")
    return tmp_path


def run(
    course: Path, *args: str, env: dict | None = None
) -> tuple[subprocess.CompletedProcess, dict]:
    report = course / "report.json"
    report.unlink(missing_ok=True)
    environment = {k: v for k, v in os.environ.items() if k != "MSDLAB_IMPL"}
    process = subprocess.run(
        [
            sys.executable,
            "-m",
            "pytest",
            "checks",
            f"--msdlab-report={report}",
            "-p",
            "no:cacheprovider",
            "-p",
            "no:hypothesispytest",  # the demo checks do not use hypothesis; saves a second
            "-p",
            "no:nbval",
            *args,
        ],
        cwd=course,
        env={**environment, **(env or {})},
        capture_output=True,
        text=True,
    )
    data = json.loads(report.read_text()) if report.exists() else {}
    return process, data


def outcomes(data: dict) -> dict[str, tuple[str, str | None]]:
    return {c["name"]: (c["outcome"], c["exception"]) for c in data["checks"]}


def test_the_students_files_by_default_even_beside_the_solutions(course):
    process, data = run(course)
    assert data["implementation"] == "assignments" and data["totals"]["earned"] == 0
    assert "msdlab: checking the task files of assignments" in process.stdout
    assert "reference answers" not in process.stdout


def test_solutions_when_asked_say_so_with_points_hidden_and_summary(course):
    process, data = run(course, "--impl=solutions")
    assert process.returncode == 0, process.stdout
    header = "msdlab: checking the task files of solutions (the reference answers, not your"
    assert header in process.stdout
    assert data["schema"] == "msdlab-check-report/1"
    assert data["implementation"] == "solutions"
    assert data["totals"] == {"points": 3, "earned": 3, "checks": 2, "passed": 2}
    answer, hidden = data["checks"]
    assert answer["nodeid"] == "checks/test_demo.py::test_answer" or answer["nodeid"].endswith(
        "test_demo.py::test_answer"
    )
    assert (answer["task"], answer["points"], answer["hidden"]) == (1, 2, False)
    assert (hidden["name"], hidden["points"], hidden["hidden"]) == ("hidden_answer", 1, True)
    assert "msdlab points" in process.stdout and "3/3 points (task1 3/3)" in process.stdout


def test_impl_option_env_fallback_and_precedence(course):
    process, data = run(course, "--impl=assignments")
    assert process.returncode == 1
    assert outcomes(data) == {
        "answer": ("failed", "NotImplementedError"),
        "hidden_answer": ("failed", "NotImplementedError"),
    }
    assert data["checks"][0]["message"] == (
        "Task 1: return 42\nin your code: assignments/task1.py, line 2, in answer"
    )  # the file and function to write
    _, data = run(course, env={"MSDLAB_IMPL": "assignments"})
    assert data["implementation"] == "assignments" and data["totals"]["earned"] == 0
    _, data = run(course, "--impl=solutions", env={"MSDLAB_IMPL": "assignments"})
    assert data["totals"]["earned"] == 3


def test_impl_path_and_physics_message(course):
    _, data = run(course, "--impl=mine")  # a path relative to the working directory
    assert data["implementation"] == str((course / "mine").resolve())
    answer = data["checks"][0]
    assert (answer["outcome"], answer["exception"]) == ("failed", "CheckFailed")
    assert answer["message"] == "the answer is 41. Usual cause: counting from 0."
    assert outcomes(data)["hidden_answer"] == ("passed", None)


def test_broken_submissions_are_reported_clearly(course):
    (course / "mine" / "task1.py").write_text("def answer(:\n    return 42\n")
    _, data = run(course, "--impl=mine")
    outcome, exception = outcomes(data)["answer"]
    assert (outcome, exception) == ("error", "SubmissionError")
    assert "task1.py could not be imported (line 1): SyntaxError" in data["checks"][0]["message"]
    (course / "mine" / "task1.py").write_text("def question():\n    return 42\n")
    _, data = run(course, "--impl=mine")
    assert outcomes(data)["answer"] == ("failed", "AttributeError")
    assert "task1.py has no 'answer'" in data["checks"][0]["message"]
    (course / "mine" / "task1.py").unlink()
    _, data = run(course, "--impl=mine")
    assert "task1.py is missing" in data["checks"][0]["message"]


def test_graded_checks_need_points(course):
    source = (course / "checks" / "test_demo.py").read_text()
    (course / "checks" / "test_demo.py").write_text(source.replace("@pytest.mark.points(2)\n", ""))
    process, _ = run(course)
    assert process.returncode == pytest.ExitCode.USAGE_ERROR
    assert "needs @pytest.mark.points(N)" in process.stderr


def test_marker_selection(course):
    _, data = run(course, "-m", "task1 and not hidden")
    assert [c["name"] for c in data["checks"]] == ["answer"]


GROUPED = """
import pytest
from hypothesis import given, settings, strategies as st

from msdlab.course.feedback import Recognised, expect

pytestmark = pytest.mark.task1


@pytest.mark.points(1)
@settings(max_examples=50, derandomize=True, database=None)
@given(n=st.integers(0, 10))
def test_two_ways(task1, n):
    task1.answer(n)


@pytest.mark.points(1)
def test_recognised(task1):
    expect(task1.answer(1) == 42, saw="the answer is 41", cause=Recognised("counting from 0"))
"""


def test_hypothesis_groups_are_the_inputs_that_failed_and_a_recognised_mistake_is_kept(course):
    """Two distinct failures of one property check are listed with their inputs, not as
    Hypothesis' ExceptionGroup; a recognised mistake is written to the report."""
    (course / "checks" / "test_demo.py").write_text(GROUPED)
    (course / "mine" / "task1.py").write_text(
        "def answer(n):\n"
        "    if n == 3:\n"
        "        raise ValueError('three')\n"
        "    if n == 5:\n"
        "        raise KeyError('five')\n"
        "    return 41\n"
    )
    _, data = run(course, "--impl=mine")
    grouped, recognised = data["checks"]
    assert grouped["exception"] == "KeyError and ValueError"
    message = grouped["message"]
    assert "Hypothesis found" not in message and message.startswith("it fails in 2 different ways")
    for failure in ("ValueError: three", "KeyError: 'five'"):
        assert re.search(rf"^[12]\. {failure}$", message, re.M), message
    assert "the input that failed: n = 3" in message and "the input that failed: n = 5" in message
    assert recognised["mistake"] == "counting from 0"
    assert recognised["message"] == (
        "the answer is 41. Your result is exactly what this mistake gives: counting from 0."
    )
