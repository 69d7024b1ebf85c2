"""A student with their own numbers reads only their own: every message the checks print
about the numbers of the template (task 1's and task 2's height and acceleration, the step
the grid lands in, task 4's grid of the cost, task 5's run of the template) holds no number
of another student's, nor of the template's defaults.

The messages are those the planted bugs (tests/course/planted/variants.py) make: each bug
is written into the student's own solution and run, as their ``msdlab check`` runs it, by
every check of task 1 (public and hidden) and by the checks of tasks 4 and 5 that take the
own numbers. Two students whose numbers all differ, from each other and from the defaults.
"""

from __future__ import annotations

import inspect
import re
from pathlib import Path

import pytest
from modules import module_at

from msdlab.course import PROJECT_ROOT, delegation, own_numbers
from msdlab.instructor import validate

CHECKS = PROJECT_ROOT / "tests" / "tasks"
SOLUTIONS = PROJECT_ROOT / "solutions"
STUDENTS = ("alice", "carol")
BUGS = module_at(Path(__file__).parent / "planted" / "variants.py", "msdlab_own_variants").BUGS
COST_BUGS = ("cost: the total time", "cost: n ignored", "cost: springs counted twice")


def landing(own: own_numbers.Numbers) -> int:
    """The step in which the template's bottom layer, at rest at ``own``'s height, lands."""
    height, speed, step = own.bottom, 0.0, 0
    while height > 0:
        speed += own.gravity * own_numbers.DT**2
        height += speed
        step += 1
    return step


def foreign(own: own_numbers.Numbers) -> dict[str, re.Pattern]:
    """What must not stand in ``own``'s messages: each number of the other student and of
    the defaults that is not also ``own``'s, by what it is."""
    others = [own_numbers.numbers(s) for s in STUDENTS] + [own_numbers.DEFAULT]
    found = {}
    for other in (o for o in others if o != own):
        numbers = {
            "y0": (other.bottom, own.bottom, "{}"),
            "g": (other.gravity, own.gravity, "{}"),
            "the landing step": (landing(other), landing(own), "{}"),
            "one less than the landing step": (landing(other) - 1, landing(own) - 1, "{}"),
            "the cost's grid": (other.cost_size, own.cost_size, r"{}³|step_cost\({},"),
        }
        for what, (theirs, mine, form) in numbers.items():
            if theirs != mine:
                number = re.escape(repr(theirs))
                pattern = form.format(*2 * [number]) if "|" in form else form.format(number)
                found[f"{what} {theirs}"] = re.compile(rf"(?<![\d.])(?:{pattern})(?![\d])")
    return found


def own_checks(task: int) -> list[validate.Check]:
    """The checks of ``task`` whose messages may speak of the numbers of the template."""
    checks = validate.collect_checks(CHECKS, task)
    if task == 1:
        return checks
    return [c for c in checks if "own_numbers" in inspect.signature(c.function).parameters]


@pytest.mark.parametrize("student", STUDENTS)
def test_every_message_speaks_of_the_students_own_numbers_only(student):
    own = own_numbers.numbers(student)
    assert own != own_numbers.DEFAULT
    delegation.install()
    forbidden, read, seen = foreign(own), [], set()
    for task in (1, 4, 5):
        checks = own_checks(task)
        solution = (SOLUTIONS / f"task{task}.py").read_text()
        bugs = [b for b in BUGS if b.task == task and (task != 4 or b.name in COST_BUGS)]
        for bug in (b for b in bugs if "ORIGIN =" not in str(b.patches)):  # a copy: not own
            source = own_numbers.personalised(task, bug.apply(solution), own)
            outcomes = validate.run_source(source, task, checks, numbers=own)
            for name, outcome in outcomes.items():
                seen.add(name)
                if not outcome.passed:
                    read.append(f"{bug.name} / {name}: {outcome.message}")
    assert {"height_after_as_template", "steps_to_floor_as_template"} <= seen
    assert {"step_cost_reports_springs_and_time", "no_damping_reproduces_the_template"} <= seen
    wrong = [
        f"{what} in {message}"
        for message in read
        for what, pattern in forbidden.items()
        if pattern.search(message)
    ]
    assert not wrong, "\n".join(wrong)
    assert any(f"step {landing(own)}" in message for message in read), "its own step is said"
