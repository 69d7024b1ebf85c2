"""The class at a glance: a class of five built as grading leaves it (a gradebook and this
run's reports), whose report must say exactly what the rows say: the points per task, each
check's failure rate, the usual causes and who had them, the hand-in times not verified;
the page works offline. And `msdlab grade` writes it after a run."""

from __future__ import annotations

import base64
import dataclasses
import re
import shutil
import statistics

import pytest

from msdlab.cli import main
from msdlab.course import PROJECT_ROOT
from msdlab.course.report import MISTAKE_SENTENCE, CheckReport, CheckResult
from msdlab.instructor.intake import Entry
from msdlab.instructor.judging.grading import Grade
from msdlab.instructor.outputs import class_report
from msdlab.instructor.outputs.class_report import CheckOutcome, ClassRow
from msdlab.instructor.points.gradebook import Gradebook

SIGN = "the springs push where they should pull"
LAYER = "counting one layer (n²)"
CHECKS = (  # task, name, points
    (1, "particle_count", 2),
    (1, "steps_to_floor", 3),
    (2, "grid_at_rest_feels_no_force", 4),
    (2, "forces_are_equal_and_opposite", 5),
)
FAILS = {  # student -> {check name: the usual cause its message names, or ""}
    "ada": {},
    "bo": {"particle_count": LAYER},
    "cy": {"particle_count": LAYER, "forces_are_equal_and_opposite": SIGN},
    "di": {"forces_are_equal_and_opposite": SIGN, "steps_to_floor": ""},
    "ed": {"particle_count": LAYER, "grid_at_rest_feels_no_force": SIGN},
}


def report_of(student: str) -> CheckReport:
    checks = []
    for task, name, points in CHECKS:
        failed = name in FAILS[student]
        cause = FAILS[student].get(name)
        message = f"saw 8 where 27 was due. Usual cause: {cause}." if cause else "saw 8."
        checks.append(
            CheckResult(f"test_task{task}.py::{name}", name, task, points, False,
                        "failed" if failed else "passed", None, message if failed else "")
        )  # fmt: skip
    return CheckReport("submission", checks)


@pytest.fixture
def graded(tmp_path) -> tuple[Gradebook, list[Grade]]:
    """Five graded students (their rows with per-check columns) and one who handed in
    nothing to grade; di's hand-in time is unknown, ed's from his own clock, ada's from
    Gradescope (a row from before the column saying who controls the time)."""
    book, grades = Gradebook(), []
    for student in FAILS:
        grade = Grade(student, report_of(student))
        book.record(grade, Entry(student, tmp_path, tmp_path), "print", detail=True)
        grades.append(grade)
    nobody = Grade("fy", None, ["no task files"])
    book.record(nobody, Entry("fy", tmp_path, tmp_path), None, detail=True)
    due = {"due": "2027-03-01T23:59+01:00"}
    book.rows["di"].update(due, late="hand-in time unknown: no late penalty")
    book.rows["ed"].update(due, handed_in="2027-03-01T20:00+00:00")
    book.rows["ed"].update(handed_in_from="file modification time", handed_in_control="student")
    book.rows["ada"].update(due, handed_in="2027-03-01T20:00+00:00")
    book.rows["ada"]["handed_in_from"] = "Gradescope's submission time"
    return book, grades


def test_the_points_per_task_are_the_rows_points(graded, tmp_path):
    book, grades = graded
    rows = class_report.rows_of(book, grades)
    columns = dict(class_report.task_statistics(rows, book.maximum))
    assert columns["task1"] == [5, 3, 3, 2, 3] and columns["task2"] == [9, 9, 4, 4, 5]
    assert "task3" not in columns  # no check grades it: nothing to show
    assert columns["total"] == [14, 12, 7, 6, 8]
    page = tmp_path / "grades.class.html"
    class_report.write_html(rows, book.maximum, page)
    text = page.read_text(encoding="utf-8")
    assert "5 of 6 students graded" in text
    mean = statistics.mean(columns["total"])
    assert re.search(rf"<th>total</th><td class=\"number\">14</td><td class=\"number\">{mean:.1f}",
                     text)  # fmt: skip


@pytest.mark.parametrize("source", ["this run's reports", "the gradebook's columns"])
def test_each_checks_failure_rate_is_what_the_rows_say(graded, source):
    book, grades = graded
    rows = class_report.rows_of(book, grades if source == "this run's reports" else [])
    rates = {rate.column: (rate.failed, rate.graded) for rate in class_report.failure_rates(rows)}
    for task, name, _ in CHECKS:  # counted here from FAILS, the class as planted
        failed = sum(name in fails for fails in FAILS.values())
        assert rates[f"task{task} {name}"] == (failed, 5), name
    ranked = [rate.column for rate in class_report.failure_rates(rows)]
    assert ranked[0] == "task1 particle_count"  # 3 of 5, the worst


def test_the_usual_causes_name_their_students(graded, tmp_path):
    book, grades = graded
    rows = class_report.rows_of(book, grades)
    causes = [(m.cause, m.students) for m in class_report.usual_causes(rows)]
    assert causes == [(LAYER, ["bo", "cy", "ed"]), (SIGN, ["cy", "di", "ed"])]
    section = class_report.summary_section(rows, "grades.class.html")
    assert f"- {LAYER}: 3 (bo, cy, ed)" in section and f"- {SIGN}: 3 (cy, di, ed)" in section


@pytest.mark.parametrize(
    ("cause", "wordings"),
    [
        ("the stiffness argument is ignored",
         ("the stiffness argument is ignored (your STIFFNESS = 0.5 used instead of k = 1)",
          "the stiffness argument is ignored (your STIFFNESS = 0.8 used instead of k = 2)")),
        ("the spacing argument is ignored",
         ("the spacing argument is ignored: your SPACING = 0.1 is the rest length",
          "the spacing argument is ignored (your SPACING = 0.1 used as the rest length)")),
    ],
)  # fmt: skip
def test_one_misconception_worded_by_several_checks_counts_once(cause, wordings):
    """Checks add the student's own numbers to a cause; the cause is still one."""
    checks = tuple(CheckOutcome(2, f"check{i}", False, text) for i, text in enumerate(wordings))
    rows = [ClassRow(s, True, {}, 0.0, checks, None) for s in ("bo", "cy")]
    (found,) = class_report.usual_causes(rows)
    assert (found.cause, found.students, found.example) == (cause, ["bo", "cy"], wordings[0])


def test_the_hand_in_times_not_verified_are_listed(graded, tmp_path):
    book, grades = graded
    rows = class_report.rows_of(book, grades)
    section = class_report.summary_section(rows, "grades.class.html")
    assert "Hand-in time not verified: 2:" in section
    assert "- hand-in time unknown: 1 (di)" in section
    assert ("- hand-in time from the file modification time, which the student's machine set: "
            "1 (ed)") in section  # fmt: skip
    assert "ada" not in section.split("not verified")[1]  # Gradescope's time is its own
    assert "Not graded: 1:\n- fy: no task files" in section
    page = tmp_path / "grades.class.html"
    class_report.write_html(rows, book.maximum, page)
    assert "hand-in time unknown: 1 (di)" in page.read_text(encoding="utf-8")


def test_the_page_works_offline_and_its_pictures_are_pngs(graded, tmp_path):
    book, grades = graded
    page = tmp_path / "grades.class.html"
    class_report.write_html(class_report.rows_of(book, grades), book.maximum, page)
    text = page.read_text(encoding="utf-8")
    assert not re.search(r"(src|href)=\"(https?:)?//", text)  # nothing to fetch
    pictures = re.findall(r'src="data:image/png;base64,([^"]+)"', text)
    assert len(pictures) == 2  # the histograms and the check × student map
    assert all(base64.b64decode(p).startswith(b"\x89PNG") for p in pictures)


def test_a_student_id_cannot_inject_markup(tmp_path):
    book = Gradebook()
    grade = Grade("<script>alert(1)</script>", report_of("bo"))
    book.record(grade, Entry(grade.submission, tmp_path, tmp_path), "print", detail=True)
    page = tmp_path / "grades.class.html"
    class_report.write_html(class_report.rows_of(book, [grade]), book.maximum, page)
    assert "<script>" not in page.read_text(encoding="utf-8")


def test_grade_writes_the_class_report_and_its_summary_section(tmp_path, capsys):
    checks = tmp_path / "checks"
    checks.mkdir()
    for name in ("conftest.py", "test_task1.py"):
        shutil.copy(PROJECT_ROOT / "tests" / "tasks" / name, checks)
    given = []
    for student, text in (("right", "return n**3"), ("layer", "return n * n")):
        given.append(tmp_path / "class" / student)
        given[-1].mkdir(parents=True)
        source = (PROJECT_ROOT / "solutions" / "task1.py").read_text(encoding="utf-8")
        (given[-1] / "task1.py").write_text(source.replace("return n**3", text), "utf-8")
    out, notes = tmp_path / "grades.csv", tmp_path / "feedback"
    common = ["--checks", str(checks), "--call-timeout", "20", "--jobs", "2"]
    assert (
        main(["grade", *map(str, given), "--out", str(out), "--feedback", str(notes), *common]) == 0
    )
    assert f"class report written to {tmp_path / 'grades.class.html'}" in capsys.readouterr().out
    page = (tmp_path / "grades.class.html").read_text(encoding="utf-8")
    assert "2 of 2 students graded" in page and "task1 particle_count" in page
    summary = (notes / "summary.md").read_text(encoding="utf-8")
    assert "## The class at a glance" in summary and "`../grades.class.html`" in summary
    assert re.search(r"- [^\n]*: 1 \(layer\)", summary), summary  # the cause the check named
    # graded again alone, the other student's results and causes stay in the report
    assert main(["grade", str(given[0]), "--out", str(out), "--feedback", str(notes), *common]) == 0
    page = (tmp_path / "grades.class.html").read_text(encoding="utf-8")
    assert "2 of 2 students graded" in page and "<td>layer</td>" in page  # who had a cause
    assert re.search(r"- [^\n]*: 1 \(layer\)", (notes / "summary.md").read_text("utf-8"))


def test_a_recognised_mistake_is_its_cause_kept_or_read_back_from_the_message():
    mistake = "the force on the far end has the sign of the near end's"
    kept = CheckResult("test_task2.py::c", "c", 2, 2, False, "failed", None,
                       f"saw 3. {MISTAKE_SENTENCE.format(mistake)}", mistake=mistake)  # fmt: skip
    stored = dataclasses.replace(kept, mistake="")  # a gradebook that keeps the message only
    assert class_report.cause_of(kept) == class_report.cause_of(stored) == mistake
    usual = dataclasses.replace(stored, message=f"saw 3. Usual cause: {SIGN}.")
    assert class_report.cause_of(usual) == SIGN


@pytest.mark.parametrize(
    ("row", "listed"),
    [
        ({"handed_in_from": "last commit", "handed_in_control": "student"}, True),
        ({"handed_in_from": "zip entry times", "handed_in_control": "instructor"}, False),
        ({"handed_in_from": "zip entry times", "handed_in_control": "unreadable"}, True),
        ({"handed_in_from": "file modification time"}, True),  # a row from before the column
        ({"handed_in_from": "Gradescope's submission time"}, False),
    ],
)
def test_who_controls_the_hand_in_time_decides_whether_it_is_verified(row, listed):
    due = {"due": "2027-03-01T23:59+01:00", "handed_in": "2027-03-01T20:00+00:00"}
    assert (class_report.unverified(due | row) is not None) == listed
    if row.get("handed_in_control") != "unreadable":  # without a due date the time is moot
        assert class_report.unverified(row) is None


@pytest.mark.parametrize("student", ["$\\frac{1}{0$", "a$b", "x_{1}$^$"])
def test_a_student_id_is_drawn_as_typed_not_as_mathtext(tmp_path, student):
    book = Gradebook()
    grade = Grade(student, report_of("bo"))
    book.record(grade, Entry(grade.submission, tmp_path, tmp_path), "print", detail=True)
    figure = class_report.heatmap(class_report.rows_of(book, [grade]))
    figure.savefig(tmp_path / "map.png")  # a mathtext parse would fail here
    labels = [label.get_text() for label in figure.axes[0].get_xticklabels()]
    assert labels == [student]
