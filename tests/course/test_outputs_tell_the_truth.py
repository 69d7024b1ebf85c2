"""Every output says the truth about each row, as an unlucky instructor or an attacker meets
it: a gradebook that is a link, a row the grader failed on, a roster that does not match
the hand-ins, a late student's feedback, a typo in the extensions, Gradescope's results.
Unit-level: rows committed to a gradebook and rendered, no grading run."""

from __future__ import annotations

import argparse
import csv
import os
import shutil
from datetime import datetime, timedelta, timezone
from pathlib import Path

import pytest

from msdlab.cli import main
from msdlab.course import PROJECT_ROOT
from msdlab.course.report import CheckReport, CheckResult
from msdlab.instructor import intake
from msdlab.instructor.intake import HandIn
from msdlab.instructor.judging import gradescope, grading
from msdlab.instructor.outputs import csv_files, output_files, render
from msdlab.instructor.points import gradebook_db
from msdlab.instructor.rules import late, term_options
from msdlab.instructor.rules.final_points import Terms

TASK1 = (PROJECT_ROOT / "solutions" / "task1.py").read_bytes()
CHECKS = [
    CheckResult("t::a", "rest_state", 1, 40, False, "passed"),
    CheckResult("t::b", "falls", 1, 35, False, "passed"),
    CheckResult("t::c", "secret", 1, 20, True, "failed", "CheckFailed", "the hidden input 7.3"),
]
DUE = datetime(2027, 3, 1, 23, 59, tzinfo=timezone(timedelta(hours=1)))


def result(identifier: str, status: str = gradebook_db.GRADED) -> gradebook_db.Result:
    report = CheckReport(identifier, list(CHECKS)) if status == gradebook_db.GRADED else None
    notes = ["grader error: the judge died"] if status == gradebook_db.GRADER_FAILED else []
    return gradebook_db.Result(identifier, f"/class/{identifier}", status, notes, report, "f1")


def rows_of(path: Path) -> dict[str, dict[str, str]]:
    return {row["id"]: row for row in csv.DictReader(path.open(encoding="utf-8"))}


def class_of(tmp_path: Path, terms: Terms | None = None) -> Path:
    """alice graded (75 of 95), dave the grader's failure, carol absent, rendered."""
    out = tmp_path / "grades.csv"
    connection = gradebook_db.connect(gradebook_db.beside(out))
    for row in (
        result("alice"),
        result("dave", gradebook_db.GRADER_FAILED),
        gradebook_db.Result("carol", "", gradebook_db.ABSENT, ["nothing handed in"]),
    ):
        gradebook_db.record(connection, row, None)  # fmt: skip
    render.render(connection, out, terms or Terms(), tmp_path / "feedback")
    connection.close()
    return out


# ------------------------------------------------- no output is written through a link
def test_a_gradebook_that_is_a_link_is_refused_and_its_target_untouched(tmp_path):
    other = tmp_path / "other-course" / "grades.db"
    gradebook_db.connect(other).close()
    before = other.read_bytes()
    (tmp_path / "grades.db").symlink_to(other)
    with pytest.raises(output_files.LinkRefused, match=r"grades\.db is a symbolic link"):
        gradebook_db.connect(tmp_path / "grades.db")
    (tmp_path / "mine").mkdir()
    (tmp_path / "mine" / "grades.db-wal").symlink_to(tmp_path / "elsewhere")
    with pytest.raises(output_files.LinkRefused, match=r"grades\.db-wal is a symbolic link"):
        gradebook_db.connect(tmp_path / "mine" / "grades.db")
    assert other.read_bytes() == before and not (tmp_path / "elsewhere").exists()


def test_grades_files_and_feedback_files_that_are_links_are_refused(tmp_path):
    out = class_of(tmp_path)
    target = tmp_path / "not-mine.md"
    target.write_text("someone else's file\n")
    (tmp_path / "feedback" / "students" / "alice.md").unlink()
    (tmp_path / "feedback" / "students" / "alice.md").symlink_to(target)
    with pytest.raises(output_files.LinkRefused, match=r"alice\.md is a symbolic link"):
        class_of(tmp_path)
    out.unlink()
    out.symlink_to(target)
    with pytest.raises(output_files.LinkRefused, match=r"grades\.csv is a symbolic link"):
        csv_files.write_csv(out, [["alice", "1"]], ["id", "total"])
    assert target.read_text() == "someone else's file\n"


# ------------------------------------------------- a row the grader failed on has no points
def test_a_grader_failed_row_has_no_points_and_a_status_in_every_output(tmp_path, capsys):
    out = class_of(tmp_path)
    rows = rows_of(out)
    assert rows["dave"]["status"] == "grader failed"
    assert {rows["dave"][c] for c in ("task1", "points", "total")} == {""}
    assert rows["carol"]["status"] == "absent" and rows["carol"]["total"] == "0"
    assert rows["alice"]["status"] == "graded" and rows["alice"]["total"] == "75"
    (tmp_path / "roster.csv").write_text("id,name,canvas_id\nalice,A,1\ncarol,C,3\ndave,D,4\n")
    exported = tmp_path / "canvas.csv"
    assert main(["export", str(out), "--roster", str(tmp_path / "roster.csv"),
                 "--format", "canvas", "--out", str(exported)]) == 0  # fmt: skip
    cells = {row["ID"]: row["msdlab"] for row in csv.DictReader(exported.open())}
    assert cells == {"": "95", "1": "75", "3": "0", "4": ""}
    said = capsys.readouterr().err
    assert "'dave': the grader failed on this submission" in said and "left empty" in said
    moodle = tmp_path / "moodle.csv"
    assert main(["export", str(out), "--roster", str(tmp_path / "roster.csv"),
                 "--format", "moodle", "--out", str(moodle)]) == 0  # fmt: skip
    dave = next(row for row in csv.DictReader(moodle.open()) if row["Full name"] == "D")
    assert (dave["msdlab"], dave["Feedback"]) == ("", "")


def test_a_grader_failed_row_taken_in_again_from_its_grades_file_keeps_no_points(tmp_path):
    out = class_of(tmp_path)
    gradebook_db.beside(out).unlink()
    assert main(["grade", "--out", str(out), "--render"]) == 0  # the CSV taken in afresh
    dave = rows_of(out)["dave"]
    assert (dave["status"], dave["total"], dave["task1"]) == ("grader failed", "", "")


# ------------------------------------------------- the roster and the hand-ins, both ways
def hand_ins(root: Path, *names: str) -> list[Path]:
    for name in names:
        (root / name).mkdir(parents=True)
        (root / name / "task1.py").write_bytes(TASK1)
    return [root / name for name in names]


def test_with_submissions_and_a_roster_nobody_is_left_unsaid(tmp_path):
    paths = hand_ins(tmp_path / "class", "alice", "mallory")
    roster = tmp_path / "roster.csv"
    roster.write_text("id,folder\nalice,class/alice\njudy,class/judy\n")
    with intake.taken_in(paths, roster) as found:
        entries = {entry.id: entry for entry in found.entries}
    assert sorted(entries) == ["alice", "judy", "mallory"]
    assert entries["alice"].problem is None
    assert entries["judy"].absent and entries["judy"].problem == "nothing handed in"
    assert intake.NOT_ON_ROSTER in entries["mallory"].problem and not entries["mallory"].absent


def test_with_a_roster_alone_a_hand_in_beside_the_listed_ones_is_named(tmp_path):
    hand_ins(tmp_path / "class", "alice", "mallory/assignments")
    (tmp_path / "class" / "notes").mkdir()  # no task files: not a hand-in
    roster = tmp_path / "roster.csv"
    roster.write_text("id,folder\nalice,class/alice\njudy,class/judy/assignments\n")
    with intake.from_roster(roster) as found:
        entries = {entry.id: entry for entry in found.entries}
    assert sorted(entries) == ["alice", "judy", "mallory"]
    assert "mallory was handed in under the id 'mallory'" in entries["mallory"].problem
    assert "class" not in entries["judy"].problem  # no folder of the grader's for a student


def test_the_summary_names_hand_ins_not_on_the_roster(tmp_path):
    out = tmp_path / "grades.csv"
    connection = gradebook_db.connect(gradebook_db.beside(out))
    problem = intake.submissions.unlisted("mallory", tmp_path / "mallory")
    gradebook_db.record(connection, gradebook_db.Result(
        "mallory", "", gradebook_db.NOT_GRADED, [problem]), None)  # fmt: skip
    render.render(connection, out, Terms(), tmp_path / "feedback")
    summary = (tmp_path / "feedback" / "summary.md").read_text()
    assert "Handed in under an id not on the roster, not graded (1): mallory." in summary


def test_a_run_with_a_roster_mismatch_and_an_extension_typo_says_each(tmp_path, capsys):
    checks = tmp_path / "course" / "tests" / "tasks"
    checks.mkdir(parents=True)
    for name in ("conftest.py", "test_task1.py"):
        shutil.copy(PROJECT_ROOT / "tests" / "tasks" / name, checks)
    paths = hand_ins(tmp_path / "class", "alice", "mallory")
    (tmp_path / "roster.csv").write_text("id,folder\nalice,class/alice\njudy,class/judy\n")
    (tmp_path / "extensions.csv").write_text("id,extension\nalcie,2d\n")
    out = tmp_path / "grades.csv"
    status = main(["grade", *map(str, paths), "--roster", str(tmp_path / "roster.csv"),
                   "--out", str(out), "--checks", str(checks), "--call-timeout", "30",
                   "--due", "2027-03-01T23:59+01:00", "--feedback", str(tmp_path / "feedback"),
                   "--extensions", str(tmp_path / "extensions.csv")])  # fmt: skip
    said = capsys.readouterr().err
    assert status == 1, said
    assert "no submission has the id 'alcie'" in said and "did you mean 'alice'?" in said
    assert "judy: nothing handed in" in said and "which is not on the roster" in said
    rows = rows_of(out)
    assert (rows["judy"]["status"], rows["judy"]["total"]) == ("absent", "0")
    assert rows["mallory"]["status"] == "not graded" and rows["alice"]["status"] == "graded"
    summary = (tmp_path / "feedback" / "summary.md").read_text()
    assert "1 of 3 submissions graded" in summary and "Nothing handed in (1): judy" in summary


# ------------------------------------------------- the student's feedback opens with the total
def test_feedback_opens_with_the_final_total_and_one_time_zone(tmp_path):
    handed = HandIn(datetime(2027, 3, 2, 10, 0, tzinfo=timezone(timedelta(hours=-5))),
                    "last commit", "student")  # fmt: skip
    terms = Terms(DUE, late.LatePolicy.parse("penalty=10%/day"), handed_in={"alice": handed})
    class_of(tmp_path, terms)
    text = (tmp_path / "feedback" / "students" / "alice.md").read_text()
    headline = text.splitlines()[2]
    assert headline.startswith("**67.5 of 95 points** (the checks gave 75;"), headline
    assert "due 2027-03-01 23:59 UTC+0100" in text and "handed in 2027-03-02 16:00 UTC+0100" in text


def test_a_students_notes_give_times_in_the_due_dates_zone_and_no_instructors_path(tmp_path):
    (alice,) = hand_ins(tmp_path / "class", "alice")
    moment = datetime(2027, 3, 2, 10, 0, tzinfo=timezone.utc).timestamp()
    os.utime(alice / "task1.py", (moment, moment))
    with intake.Intake(intake.Rules(due_of=lambda identifier: DUE)) as found:
        (note,) = found.add("alice", alice).notes
    assert note == "hand-in time not verified: file modification time " \
                   "(2027-03-02T11:00+01:00) set by the student's machine"  # fmt: skip
    out = tmp_path / "grades.csv"
    connection = gradebook_db.connect(gradebook_db.beside(out))
    place = tmp_path / "class" / "mallory"
    why = f"not graded: mallory resolves to {tmp_path}/x, outside the folder {place.parent}"
    gradebook_db.record(connection, gradebook_db.Result(
        "mallory", str(place), gradebook_db.NOT_GRADED, [why]), None)  # fmt: skip
    render.render(connection, out, Terms(), tmp_path / "feedback")
    text = (tmp_path / "feedback" / "students" / "mallory.md").read_text()
    assert "resolves to x, outside the folder class" in text and str(tmp_path) not in text


def test_a_forged_time_at_the_end_of_the_calendar_is_charged_not_a_crash(tmp_path):
    handed = HandIn(datetime(9999, 12, 31, 23, 59, tzinfo=timezone.utc), "last commit", "student")
    terms = Terms(
        DUE, late.LatePolicy.parse("penalty=10%/day,cap=50%"), handed_in={"alice": handed}
    )
    assert rows_of(class_of(tmp_path, terms))["alice"]["total"] == "37.5"


def test_a_typo_in_the_extensions_is_warned_about_and_a_lookalike_refused():
    args = argparse.Namespace(extensions=Path("extensions.csv"))
    terms = Terms(DUE, own_due={"bbo": DUE, "Alice": DUE, "bob": DUE})
    found = {
        p.what: p for p in term_options.extensions_against_class(args, terms, {"alice", "bob"})
    }
    assert not found["no submission has the id 'bbo'"].refused
    assert "did you mean 'bob'?" in str(found["no submission has the id 'bbo'"])
    assert found["no submission has the id 'Alice'"].refused
    assert "did you mean 'alice'" in str(found["no submission has the id 'Alice'"])


# ------------------------------------------------- Gradescope says what the local feedback says
def test_gradescope_shows_hidden_checks_as_points_and_no_note_about_the_grader():
    notes = ["graded with the weaker isolation 'process'", "task9.py was left out: x"]
    grade = grading.Grade("submission", CheckReport("s", list(CHECKS)), notes, 1.0)
    content = gradescope.results(grade, "after_published")
    assert "isolation" not in str(content) and "task9.py was left out" in content["output"]
    hidden = [t for t in content["tests"] if t["visibility"] == "after_published"]
    assert hidden == [{"name": "Task 1: 1 hidden check", "number": "1.hidden", "score": 0,
                       "max_score": 20, "status": "failed", "output": "",
                       "visibility": "after_published"}]  # fmt: skip
    assert "7.3" not in str(content) and "secret" not in str(content)
