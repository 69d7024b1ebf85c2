"""The planted-bug set (tests/course/planted/variants.py): every planted bug loses points in
its own task with a message that names its cause, no correct alternative loses a point, and
a submission gets the same outcome from every check in one process and through the grader.

Trivial answers (`msdlab.instructor.trivial`: zeros, the input, constants, NaN, inf, empty
or complex arrays) earn no point at all.

The set runs in this process (`msdlab.instructor.validate.run_source`): a bug runs the check
that must catch it, and the checks reaching what it changes up to the first that fails (the
message a student reads first); an alternative every check that reaches the functions it
changes.
"""

from __future__ import annotations

import shutil
import subprocess
import sys
from pathlib import Path

import pytest
from modules import module_at

from msdlab.course import PROJECT_ROOT, TASKS, delegation
from msdlab.course.report import CheckReport
from msdlab.instructor import trivial, validate
from msdlab.instructor.judging import grading

CHECKS = PROJECT_ROOT / "tests" / "tasks"
SOLUTIONS = PROJECT_ROOT / "solutions"


def _variants():
    return module_at(Path(__file__).parent / "planted" / "variants.py", "msdlab_planted_variants")


VARIANTS = _variants()
BUGS, ALTERNATIVES = VARIANTS.BUGS, VARIANTS.ALTERNATIVES


def ids(variants):
    return [f"task{v.task}: {v.name}" for v in variants]


class Harness:
    """The checks of each task, the solutions, and which checks reach which function."""

    def __init__(self) -> None:
        delegation.install()
        self.checks = {task: validate.collect_checks(CHECKS, task) for task in TASKS}
        self.sources = {task: (SOLUTIONS / f"task{task}.py").read_text() for task in TASKS}
        self._reached: dict[int, dict[str, set]] = {}

    def check(self, task: int, name: str) -> validate.Check:
        found = [c for c in self.checks[task] if c.name == name]
        assert found, f"task {task} has no check {name}"
        return found[0]

    def concerned(self, variant) -> list[validate.Check]:
        """The checks that reach a function the variant changes (all of them where it changes
        the file's constants)."""
        task, source = variant.task, self.sources[variant.task]
        if task not in self._reached:
            self._reached[task] = validate.reached(source, task, self.checks[task])
        changed = {
            validate.definition_at(source, source[: source.index(old)].count("\n") + 1)
            for old, _ in variant.patches
        }
        if None in changed:
            return self.checks[task]
        return [c for c in self.checks[task] if changed & self._reached[task][c.name]]


@pytest.fixture(scope="module")
def harness() -> Harness:
    return Harness()


def test_the_set_is_large_enough_and_applies_to_the_solutions():
    for task in TASKS:
        assert sum(v.task == task for v in BUGS) >= 12, f"task {task}: fewer than 12 bugs"
        assert sum(v.task == task for v in ALTERNATIVES) >= 8, f"task {task}: < 8 alternatives"
    for variant in BUGS + ALTERNATIVES:
        source = (SOLUTIONS / f"task{variant.task}.py").read_text()
        assert variant.apply(source) != source
    assert all(bug.check and bug.words for bug in BUGS), "every bug names its check and cause"


@pytest.mark.parametrize("bug", BUGS, ids=ids(BUGS))
def test_a_planted_bug_loses_points_and_the_first_failing_check_names_its_cause(bug, harness):
    """The bug's own check fails naming its cause, and so does the task's first failing
    check: the student reads it first, so it must not point elsewhere."""
    source = bug.apply(harness.sources[bug.task])
    outcomes = validate.run_source(
        source, bug.task, harness.concerned(bug), seconds=300, stop_at_first_failure=True
    )
    failed = [name for name, outcome in outcomes.items() if not outcome.passed]
    assert failed, f"no check reaching the changed code catches '{bug.name}'"
    assert bug.words in outcomes[failed[0]].message, (
        f"{failed[0]} (first to fail) says: {outcomes[failed[0]].message}"
    )
    own = harness.check(bug.task, bug.check)
    if own.name not in outcomes:  # after the first failure, or reaching other code
        outcomes |= validate.run_source(source, bug.task, [own], seconds=120)
    assert not outcomes[own.name].passed, f"{own.name} does not catch '{bug.name}'"
    assert bug.words in outcomes[own.name].message, f"{own.name} says: {outcomes[own.name].message}"


def test_springs_listed_twice_are_said_as_such_with_an_example(harness):
    """Springs listed from both ends: the pairs check shows a pair listed twice (never an
    empty example), and the rest lengths' check says how many springs there are, not that
    the body has none."""
    bug = next(b for b in BUGS if b.name == "springs listed from both ends")
    checks = [
        harness.check(4, "grid_springs_each_pair_once"),
        harness.check(4, "rest_lengths_unstressed"),
    ]
    outcomes = validate.run_source(bug.apply(harness.sources[4]), 4, checks, seconds=120)
    pairs, rest = (outcomes[c.name].message for c in checks)
    assert "listed twice (e.g. particles (0, 1))" in pairs, pairs
    assert "850 springs where the (3, 4, 5) grid has 425" in rest, rest
    assert "without real springs" not in rest and "[]" not in pairs


@pytest.mark.parametrize("kind", trivial.KINDS)
@pytest.mark.parametrize("task", TASKS)
def test_a_trivial_answer_earns_no_point(task, kind, harness):
    """The solution answering zeros, its input, constants, NaN, inf, empty or complex arrays
    fails every check of its task."""
    source = trivial.answer_source(harness.sources[task], kind)
    outcomes = validate.run_source(source, task, harness.checks[task], seconds=60)
    assert not [name for name, outcome in outcomes.items() if outcome.passed]


@pytest.mark.parametrize("alternative", ALTERNATIVES, ids=ids(ALTERNATIVES))
def test_a_correct_alternative_loses_no_point(alternative, harness):
    checks = harness.concerned(alternative)
    assert checks, "an alternative must change code that some check reaches"
    source = alternative.apply(harness.sources[alternative.task])
    outcomes = validate.run_source(source, alternative.task, checks, seconds=120)
    lost = [f"{name}: {o.exception}: {o.message}" for name, o in outcomes.items() if not o.passed]
    assert not lost, "\n".join(lost)


# ------------------------------------------------------------------ one verdict everywhere
SAME_VERDICT = {  # one planted bug per task: in-place changes of arguments and delegation
    1: "verlet_step in place",
    2: "positions centred in place",
    3: "rotation delegated to msd.rotation_matrix",
    4: "springs delegated to Body.grid",
    5: "velocity damped in place",
}


def in_one_process(folder: Path, report: Path) -> CheckReport:
    command = [
        sys.executable, "-m", "pytest", str(CHECKS), f"--impl={folder}", "-q", "--tb=no",
        f"--msdlab-report={report}", "-p", "no:cacheprovider", "-p", "no:nbval",
    ]  # fmt: skip
    subprocess.run(command, cwd=PROJECT_ROOT, capture_output=True, check=False, timeout=600)
    return CheckReport.read(report)


def test_every_check_judges_alike_in_one_process_and_through_the_grader(tmp_path):
    folder = tmp_path / "planted"
    shutil.copytree(SOLUTIONS, folder)
    chosen = {v.task: v for v in BUGS if SAME_VERDICT.get(v.task) == v.name}
    assert sorted(chosen) == list(TASKS)
    for task, bug in chosen.items():
        path = folder / f"task{task}.py"
        path.write_text(bug.apply(path.read_text()))
    local = in_one_process(folder, tmp_path / "report.json")
    graded = grading.grade(grading.Submission("planted", folder), CHECKS, timeout=600.0)
    assert graded.report is not None, graded.notes
    here = {c.name: c.outcome for c in local.checks}
    there = {c.name: c.outcome for c in graded.report.checks}
    assert here == there
    for task, bug in chosen.items():
        assert here[bug.check] == "failed", f"task {task}: {bug.check} missed '{bug.name}'"
    assert any(note.startswith("task3: delegation refused") for note in graded.notes)
