"""Each student's own numbers: two students get different template parameters from their
roster ids, each one's work passes against their own numbers and fails against the
other's (in ``msdlab check``'s pytest run and in the grader), and with the switch off,
the default, the checks and the release are those of the template."""

from __future__ import annotations

import json
import re
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from modules import module_at

from msdlab.course import PROJECT_ROOT, oracles, own_numbers
from msdlab.course.report import CheckReport
from msdlab.instructor import release, templates
from msdlab.instructor.judging import grading

CHECKS = PROJECT_ROOT / "tests" / "tasks"
TEMPLATE_1 = (PROJECT_ROOT / "assignments" / "task1.py").read_text(encoding="utf-8")
SOLUTION_1 = (PROJECT_ROOT / "solutions" / "task1.py").read_text(encoding="utf-8")
FLOOR_CHECK = "steps_to_floor_as_template"


def own_solution(folder: Path, student: str) -> Path:
    """The reference answer of task 1 in ``student``'s own template (their id beside it)."""
    folder.mkdir(parents=True)
    text = own_numbers.personalised(1, SOLUTION_1, own_numbers.numbers(student))
    (folder / "task1.py").write_text(text, encoding="utf-8")
    own_numbers.write_student(folder, student)
    return folder


def check_task1(folder: Path, report: Path, *options: str) -> CheckReport:
    """Task 1's public checks on ``folder``, as ``msdlab check 1`` runs them."""
    command = [sys.executable, "-m", "pytest", str(CHECKS / "test_task1.py"), f"--impl={folder}",
               f"--msdlab-report={report}", "-q", "--tb=no", "-p", "no:cacheprovider",
               "-p", "no:nbval", *options]  # fmt: skip
    subprocess.run(command, cwd=PROJECT_ROOT, capture_output=True, check=False)
    return CheckReport.read(report)


def failed(report: CheckReport) -> set[str]:
    return {check.name for check in report.checks if not check.passed}


def test_two_students_get_different_numbers_from_their_ids():
    alice, carol = own_numbers.numbers("alice"), own_numbers.numbers("carol")
    assert alice == own_numbers.numbers("alice") == own_numbers.numbers(" alice ")
    assert alice.bottom != carol.bottom and alice.gravity != carol.gravity
    assert alice.cost_size != carol.cost_size
    assert alice.bottom in own_numbers.HEIGHTS and carol.gravity in own_numbers.ACCELERATIONS


def test_the_defaults_are_the_templates_numbers():
    """Off (no student): the checks use exactly the numbers they always used."""
    template = module_at(PROJECT_ROOT / "assignments" / "task1.py", "template_task1")
    default = own_numbers.numbers(None)
    assert default.bottom == template.ORIGIN[1] and default.gravity == template.GRAVITY[1]
    assert default.gravity == oracles.TEMPLATE_GRAVITY[1] and default.cost_size == 6
    assert own_numbers.personalised(1, TEMPLATE_1, default) == TEMPLATE_1


def test_own_template_changes_only_its_numbers():
    alice = own_numbers.numbers("alice")
    own = templates.render(PROJECT_ROOT / "solutions", alice)["task1.py"]
    changed = [(a, b) for a, b in zip(TEMPLATE_1.splitlines(), own.splitlines()) if a != b]
    shown = own_numbers.shown(alice)
    assert changed == [
        ("ORIGIN = (-1.0, 1.5, -1.0)  # position of particle (0, 0, 0)",
         f"ORIGIN = (-1.0, {alice.bottom}, -1.0)  # position of particle (0, 0, 0)"),
        ("GRAVITY = (0.0, -0.001, 0.0)  # the template's acceleration a",
         f"GRAVITY = (0.0, {alice.gravity}, 0.0)  # the template's acceleration a"),
        ("    y in [1.5, 1.5 + EDGE).", f"    y in [{alice.bottom}, {alice.bottom} + EDGE)."),
        ("    your template (y0 = ORIGIN[1] = 1.5) the exact free fall y0 + ½ g t²",
         f"    your template (y0 = ORIGIN[1] = {alice.bottom}) the exact free fall y0 + ½ g t²"),
        ("    would land at t = 54.8: the template's steps fall a little faster.",
         f"    would land at t = {shown['fall_time']}: the template's steps fall a little "
         "faster."),
    ]  # fmt: skip


@pytest.mark.parametrize("student", ["alice", "carol", "dave"])
def test_the_given_code_runs_on_the_students_own_numbers(student, tmp_path):
    """The template's given code computes from its constants: the student's own grid starts
    at their y0, and their running template reaches the floor in the step the check asks
    for, close to the time the docstring names; the docstring names no step, so neither
    the right one nor one a check rejects."""
    own = own_numbers.numbers(student)
    text = templates.render(PROJECT_ROOT / "solutions", own)["task1.py"]
    (tmp_path / "task1.py").write_text(text, encoding="utf-8")
    template = module_at(tmp_path / "task1.py", f"own_task1_{student}")
    grid = template.initial_grid(4)
    assert grid[:, 0, :, 1].min() == pytest.approx(own.bottom, abs=1e-12)
    old, current, new = grid.copy(), grid.copy(), np.empty_like(grid)
    step = 0
    while current[..., 1].min() > template.FLOOR:
        template.msd_kernel(old, current, new)
        old, current, new = current, new, old
        step += 1
    expected = oracles.template_run(
        oracles.template_positions((3, 2, 3), 0.1, (-1.0, own.bottom, -1.0)), 1000,
        acceleration=(0.0, own.gravity, 0.0),
    )  # fmt: skip
    assert step == int(np.flatnonzero(expected[:, :, 0, :, 1].min(axis=(1, 2)) <= 0.0)[0])
    landing = float(own_numbers.shown(own)["fall_time"]) / own_numbers.DT
    assert abs(step - landing) < 2
    docstring = template.steps_to_floor.__doc__
    assert not [n for n in range(step - 2, step + 3) if number_in(str(n), docstring)]


def test_a_student_reads_no_number_of_the_defaults_where_theirs_differ(tmp_path):
    """The release of a student whose numbers both differ from the defaults: their task
    files and notebooks of tasks 1 and 2 show their numbers, none of the defaults', and no
    marker."""
    student = next(s for s in ("alice", "bob", "carol", "dave", "erin") if different(s))
    own = own_numbers.numbers(student)
    (tmp_path / "course").mkdir()
    course = shutil.copytree(PROJECT_ROOT, tmp_path / "course", dirs_exist_ok=True,
                             ignore=shutil.ignore_patterns(".venv", ".git", "_build"))  # fmt: skip
    (course / own_numbers.SETTINGS_FILE).write_text('{"own_numbers": true}')
    out = tmp_path / "release"
    release.build(out, course, student=student)
    files = {
        task: (out / "assignments" / f"task{task}.py").read_text(encoding="utf-8")
        for task in (1, 2)
    }
    notebooks = {
        task: "\n".join(
            cell["source"]
            for cell in json.loads((out / "notebooks" / f"task{task}.ipynb").read_text())["cells"]
        )
        for task in (1, 2)
    }
    default = own_numbers.shown(own_numbers.DEFAULT)
    for text in (*files.values(), *notebooks.values()):
        assert "{{" not in text and number_in(str(own.bottom), text)
        assert not number_in(default["y0"], text) and not number_in(default["g"], text)
    task1, notebook = files[1], notebooks[1]
    assert not number_in(default["fall_time"], task1)
    assert number_in(own_numbers.shown(own)["fall_time"], task1)
    assert f"(0, {own.gravity}, 0)" in notebook


def number_in(number: str, text: str) -> list[str]:
    """The lines of ``text`` where ``number`` stands as a number of its own."""
    pattern = re.compile(rf"(?<![\d.]){re.escape(number)}(?![\d])")
    return [line for line in text.splitlines() if pattern.search(line)]


def different(student: str) -> bool:
    own, default = own_numbers.numbers(student), own_numbers.DEFAULT
    return own.bottom != default.bottom and own.gravity != default.gravity


def test_an_unknown_marker_is_refused_with_the_names_it_takes():
    with pytest.raises(ValueError, match=r"task1\.py: no number named y1 .* y0, g"):
        own_numbers.filled("y = {{ y1 }}", own_numbers.DEFAULT, "task1.py")


def test_msdlab_check_says_the_numbers_are_the_students_own(tmp_path):
    assert own_numbers.announced(tmp_path) is None
    own_numbers.write_student(tmp_path, "alice")
    alice = own_numbers.numbers("alice")
    line = own_numbers.announced(tmp_path)
    assert "your own numbers (student alice)" in line
    assert (
        f"y0 = ORIGIN[1] = {alice.bottom}" in line and f"g = GRAVITY[1] = {alice.gravity}" in line
    )


def test_each_passes_against_their_own_numbers_and_fails_against_the_others(tmp_path):
    alice = own_solution(tmp_path / "alice", "alice")
    carol = own_solution(tmp_path / "carol", "carol")
    own_alice = check_task1(alice, tmp_path / "a.json")  # the id from student.json
    own_carol = check_task1(carol, tmp_path / "c.json")
    assert own_alice.earned == own_alice.points > 0 and own_carol.earned == own_carol.points
    handed = check_task1(alice, tmp_path / "ac.json", "--student=carol")  # alice's answers
    assert failed(handed) == {FLOOR_CHECK}  # ... handed to carol


def test_without_own_numbers_nothing_changes(tmp_path):
    """No course.json: the switch is off, the checks use the template's numbers, and a
    release for one student is refused with the way to switch it on."""
    assert not own_numbers.enabled(PROJECT_ROOT)
    folder = tmp_path / "plain"
    folder.mkdir()
    (folder / "task1.py").write_text(SOLUTION_1, encoding="utf-8")
    assert failed(check_task1(folder, tmp_path / "plain.json")) == set()
    with pytest.raises(ValueError, match=r'set "own_numbers": true in .*course\.json'):
        release.build(tmp_path / "out", PROJECT_ROOT, student="alice")


def test_the_settings_switch_is_checked(tmp_path):
    (tmp_path / "course.json").write_text('{"own_numbers": "yes"}')
    with pytest.raises(ValueError, match='"own_numbers" must be true or false'):
        own_numbers.enabled(tmp_path)
    (tmp_path / "course.json").write_text(json.dumps({"own_numbers": True}))
    assert own_numbers.enabled(tmp_path)
    with pytest.raises(ValueError, match="one release per student with --student ID"):
        release.build(tmp_path / "out", tmp_path)


def test_a_release_for_one_student_holds_their_numbers(tmp_path):
    assignments = shutil.copytree(PROJECT_ROOT / "assignments", tmp_path / "assignments")
    release._personalise(assignments, PROJECT_ROOT / "solutions", "carol")
    carol = own_numbers.numbers("carol")
    for task in own_numbers.OWN_CONSTANTS:  # task 2 is the template with springs
        text = (assignments / f"task{task}.py").read_text()
        assert f"ORIGIN = (-1.0, {carol.bottom}, -1.0)" in text
        assert f"GRAVITY = (0.0, {carol.gravity}, 0.0)" in text
    assert own_numbers.student_of(assignments) == "carol"
    for task in (3, 4, 5):
        assert (assignments / f"task{task}.py").read_bytes() == (
            PROJECT_ROOT / "assignments" / f"task{task}.py"
        ).read_bytes()


def test_the_grader_grades_each_against_the_roster_ids_numbers(tmp_path):
    checks = tmp_path / "checks"
    checks.mkdir()
    for name in ("conftest.py", "test_task1.py"):
        shutil.copy(CHECKS / name, checks)
    alice = own_solution(tmp_path / "alice", "alice")
    (alice / own_numbers.STUDENT_FILE).write_text('{"id": "carol"}')  # not trusted
    options = dict(own_numbers=True, call_timeout=20.0, isolation="process")
    own = grading.grade(grading.Submission("alice", alice), checks, **options)
    handed = grading.grade(grading.Submission("carol", alice), checks, **options)
    assert own.graded and own.report.earned == own.report.points, own.notes
    assert failed(handed.report) == {FLOOR_CHECK}
