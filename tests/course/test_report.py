"""The check report as the student reads it: one mistake named once, one row for one error,
the file and function of every to-do, the same lines in the command and the notebook."""

from __future__ import annotations

import re

from msdlab.course.report import MISTAKE_SENTENCE, CheckReport, CheckResult
from msdlab.instructor.judging.grading import Grade
from msdlab.instructor.outputs import feedback

LAMBDA_IGNORED = "λ is ignored: this is eq. (1.3)"


def failed(name: str, message: str, task: int = 5, points: int = 2, **fields) -> CheckResult:
    fields.setdefault("exception", "CheckFailed")
    return CheckResult(
        f"test_task{task}.py::{name}",
        name,
        task,
        points,
        False,
        "failed",
        message=message,
        **fields,
    )


def recognised(name: str, saw: str) -> CheckResult:
    message = f"{saw}. {MISTAKE_SENTENCE.format(LAMBDA_IGNORED)}"
    return failed(name, message, mistake=LAMBDA_IGNORED)


def passed(name: str, task: int = 5) -> CheckResult:
    return CheckResult(f"test_task{task}.py::{name}", name, task, 3, False, "passed")


def test_a_recognised_mistake_is_named_once_and_the_checks_it_fails_refer_to_it():
    report = CheckReport(
        "alice",
        [
            recognised("one_step_is_equation_1_4", "with λ = 0.3 particle 1 moves to (0, 1, 0)"),
            passed("no_damping_reproduces_the_template"),
            recognised("damping_removes_energy", "with λ = 0.01 99 % of the energy is left"),
            failed("damping_outside_0_to_1_is_refused", "DampedVerlet(1.0) was accepted."),
        ],
    )
    table, details = report.table(), report.details()
    assert re.search(r"one_step_is_equation_1_4 +0/2  FAILED  see \[1\]", table)
    assert re.search(r"damping_removes_energy +0/2  FAILED  see \[1\]", table)
    assert re.search(r"refused +0/2  FAILED  DampedVerlet\(1.0\) was accepted.", table)
    assert details.count(LAMBDA_IGNORED) == 1 and "[2]" not in details
    assert f"recognised mistake: {LAMBDA_IGNORED}." in details
    assert "one_step_is_equation_1_4: with λ = 0.3 particle 1 moves to (0, 1, 0)." in details
    assert "damping_removes_energy: with λ = 0.01 99 % of the energy is left." in details
    assert "exactly what this mistake gives" not in details


def test_one_error_raised_in_every_check_is_one_row_whatever_the_shapes():
    where = "in your code: assignments/task2.py, line 54, in spring_acceleration\n    a += f[:2]"
    report = CheckReport(
        "bob",
        [
            failed(
                name,
                f"operands could not be broadcast with shapes {shape}\n{where}",
                task=2,
                exception="ValueError",
            )
            for name, shape in (("rest", "(1,3) (1,2)"), ("sign", "(2,3) (2,2)"))
        ]
        + [
            failed(
                "rotation",
                f"operands could not be broadcast with shapes (3,3) (3,2)\n{where}\n"
                "it fails whatever the input (tried first: seed = 0)",
                task=2,
                exception="ValueError",
            )
        ],
    )
    table, details = report.table(), report.details()
    assert "task2 (all 3 checks)" in table and table.count("see [") == 1
    assert details.count("ValueError") == 1 and details.count("line 54") == 1
    assert "it fails whatever the input (tried first: seed = 0)" in details


def test_every_to_do_names_the_file_and_the_function_to_write():
    todo = "Task 2: sum eq. (1.2) over the neighbours of every particle.\n"
    report = CheckReport(
        "template",
        [
            failed(
                name,
                todo + "in your code: assignments/task2.py, line 51, in spring_acceleration",
                task=2,
                exception="NotImplementedError",
            )
            for name in ("rest", "sign")
        ],
    )
    assert report.checks[0].summary == (
        "to do in assignments/task2.py, spring_acceleration: sum eq. (1.2) over the neighbours "
        "of every particle."
    )
    assert "to do in assignments/task2.py, spring_acceleration: sum" in report.details()


def test_the_printout_ends_with_the_score_and_what_the_hidden_checks_are_worth():
    report = CheckReport("alice", [passed("a"), recognised("b", "it moved")])
    text = report.printout(100, hidden_worth=5)
    assert text.splitlines()[-1].startswith("  b: it moved")
    assert "public 3 of 5 points; hidden checks worth 5 more run when graded" in text
    assert text.index("total: 3/5") < text.index("public 3 of 5") < text.index("in full:")


def test_the_students_feedback_names_a_mistake_once():
    report = CheckReport(
        "alice",
        [
            recognised("one_step_is_equation_1_4", "particle 1 moves to (0, 1, 0)"),
            recognised("damping_removes_energy", "99 % of the energy is left"),
        ],
    )
    text = feedback.for_student(Grade("alice", report, notes=[], seconds=1.0))
    assert text.count(LAMBDA_IGNORED) == 1
    assert "> 99 % of the energy is left. The same mistake as in one_step_is_equation_1_4." in text
