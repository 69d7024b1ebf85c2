"""The instructor's pages meet WCAG 2.1 AA as far as axe-core can check, in headless
Chromium: the class report (grades.class.html) and the similarity page. Their pictures
carry words: a text alternative, and the numbers beside them in a table."""

from __future__ import annotations

import contextlib
import io
from pathlib import Path

import pytest
from accessibility import axe_violations, needs_axe
from browser import launch
from modules import module_at

from msdlab.cli import main
from msdlab.course.report import CheckReport, CheckResult
from msdlab.instructor.intake import Entry
from msdlab.instructor.judging.grading import Grade
from msdlab.instructor.outputs import class_report
from msdlab.instructor.points.gradebook import Gradebook

pytestmark = [*needs_axe, pytest.mark.timeout(300)]

TESTS = Path(__file__).resolve().parents[1]
CHECKS = ((1, "particle_count", 2), (1, "steps_to_floor", 3), (2, "grid_at_rest", 4))
FAILS = {"ada": set(), "bo": {"particle_count"}, "cy": {"particle_count", "grid_at_rest"}}


def report_of(student: str) -> CheckReport:
    checks = [
        CheckResult(f"test_task{task}.py::{name}", name, task, points, False,
                    "failed" if name in FAILS[student] else "passed", None,
                    "saw 8. Usual cause: counting one layer." if name in FAILS[student] else "")
        for task, name, points in CHECKS
    ]  # fmt: skip
    return CheckReport("submission", checks)


@pytest.fixture(scope="module")
def class_page(tmp_path_factory) -> Path:
    """The class report of three students graded and one with nothing to grade."""
    folder = tmp_path_factory.mktemp("class")
    book, grades = Gradebook(), []
    for student in FAILS:
        grades.append(Grade(student, report_of(student)))
        book.record(grades[-1], Entry(student, folder, folder), "print", detail=True)
    book.record(
        Grade("di", None, ["no task files"]), Entry("di", folder, folder), None, detail=True
    )
    page = folder / "grades.class.html"
    class_report.write_html(class_report.rows_of(book, grades), book.maximum, page)
    return page


@pytest.fixture(scope="module")
def similarity_page(tmp_path_factory) -> Path:
    """The similarity page of three students of the planted class of tests/course/similarity:
    a student, a disguised copy, one who wrote their own."""
    pytest.importorskip("copydetect", reason="needs copydetect (pip install -e '.[grade]')")
    copies = module_at(TESTS / "course" / "similarity" / "copies.py", "msdlab_planted_copies")
    root = tmp_path_factory.mktemp("similarity")
    folders = copies.write_class(root / "class")
    with contextlib.redirect_stdout(io.StringIO()):
        given = [str(folders[student]) for student in ("original", "renamed", "honest_plain")]
        assert main(["similarity", *given, "--out", str(root / "report")]) == 0
    return root / "report" / "similarity.html"


@pytest.fixture(scope="module")
def browser():
    from playwright.sync_api import sync_playwright

    with sync_playwright() as playwright:
        browser = launch(playwright)
        yield browser
        browser.close()


@pytest.mark.parametrize("which", ["class_page", "similarity_page"])
def test_the_page_breaks_no_wcag_rule_axe_checks(which, request, browser):
    page = browser.new_page(viewport={"width": 1280, "height": 900})
    try:
        page.goto(request.getfixturevalue(which).as_uri())
        violations = axe_violations(page, best_practice=True)
        assert not violations, "\n".join(violations)
    finally:
        page.close()


def test_the_check_map_says_each_result_in_marks_and_words_not_colour_alone(tmp_path):
    """Each failed cell of the map is marked × and each cell not run –, and the table
    beside it says every student's result of every check in words."""
    book, grades = Gradebook(), [Grade(s, report_of(s)) for s in FAILS]
    first_only = report_of("ada")
    grades.append(Grade("ed", CheckReport("submission", first_only.checks[:1])))  # 2 not run
    for grade in grades:
        book.record(grade, Entry(grade.submission, tmp_path, tmp_path), "print", detail=True)
    rows = class_report.rows_of(book, grades)
    marks = class_report.heatmap(rows).axes[0].collections  # the ×s, then the dashes
    failed = sum(len(fails) for fails in FAILS.values())
    assert [len(mark.get_offsets()) for mark in marks] == [failed, 2]
    class_report.write_html(rows, book.maximum, tmp_path / "grades.class.html")
    page = (tmp_path / "grades.class.html").read_text(encoding="utf-8")
    table = page.split("The map as a table")[1].split("</details>")[0]
    assert table.count("<td>✗ failed</td>") == failed and table.count("<td>not run</td>") == 2
    assert table.count("<td>passed</td>") == (len(FAILS) + 1) * len(CHECKS) - failed - 2
    for student in [*FAILS, "ed"]:
        assert f"<th scope='row'>{student}</th>" in table
