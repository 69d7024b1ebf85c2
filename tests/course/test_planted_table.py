"""The docs page of what each planted mistake costs (docs/instructor/mistakes.md) is current:
made from today's planted bugs, solutions and checks, and saying what the checks say."""

from __future__ import annotations

import re
from pathlib import Path

from modules import module_at

from msdlab.course import delegation
from msdlab.instructor import validate

table = module_at(Path(__file__).parent / "planted" / "table.py", "msdlab_planted_table")


def page() -> str:
    return table.PAGE.read_text(encoding="utf-8")


def failing(mistake: str) -> set[str]:
    """The checks the page says ``mistake`` fails."""
    found = re.search(rf"^\| {re.escape(mistake)} \| (.*?) \|", page(), re.M)
    assert found, f"no row for {mistake!r}"
    return set(re.findall(r"`(\w+)`", found[1]))


def test_every_task_section_was_made_from_the_current_bugs_solutions_and_checks():
    assert page().startswith(table.INTRODUCTION)
    stale = table.stale(page())
    assert not stale, (
        f"{table.PAGE} is out of date for tasks {stale}: run `python tests/course/planted/"
        f"table.py` from the root of the checkout"
    )


def test_a_row_says_what_the_checks_say_today():
    delegation.install()
    bug = next(b for b in table.variants.BUGS if b.name == "damping applied to the whole update")
    checks = validate.collect_checks(table.CHECKS, bug.task)
    total = sum(c.points for c in checks)
    assert table.row(bug, checks, total) in page()


def test_a_mistake_costs_the_checks_of_what_it_gets_wrong():
    """Forgetting the damping, or damping the force's term too, fails the damping's checks
    only: eq. (1.3), the template's trajectory and the measurement keep their points."""
    verlet = {
        "one_step_is_equation_1_3",
        "velocity_dependent_forces_see_the_velocity",
        "no_damping_reproduces_the_template",
        "measured_stable_dt_as_predicted",
        "one_step_in_2d_and_3d",
    }
    for mistake in ("damping ignored", "damping applied to the whole update"):
        assert "damping_acts_on_velocity_only" in failing(mistake)
        assert not failing(mistake) & verlet, mistake
    assert failing("constants copied from another student") == {"steps_to_floor_as_template"}
