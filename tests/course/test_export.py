"""``msdlab export``: the grades as Canvas, Moodle and plain CSV files, read back; from the
gradebook, or from the grades file of a course graded before it."""

from __future__ import annotations

import csv
from pathlib import Path

import pytest

from msdlab.cli import main
from msdlab.course.report import CheckReport, CheckResult
from msdlab.instructor.outputs import render
from msdlab.instructor.points import gradebook_db
from msdlab.instructor.rules.final_points import Terms

GRADES = """id,source,task1,task2,task3,task4,task5,points,due,handed_in,handed_in_from,late,\
late_penalty,adjustment,total,notes,fingerprint
(max points),,15,20,20,15,25,95,,,,,,,95,,
alice,{root}/class/alice/assignments,15,20,0,0,0,35,,,,,,-2,33,,abc
"bob, jr",{root}/class/bob.zip,15,0,0,0,0,15,,,,,1.5,,13.5,,def
"""


@pytest.fixture
def grades(tmp_path: Path) -> Path:
    path = tmp_path / "grades.csv"
    path.write_text(GRADES.format(root=tmp_path))
    (tmp_path / "grades.adjustments.csv").write_text(
        "id,task,change,reason,note\nalice,,-2,report handed in late,asked by email\n"
    )
    (tmp_path / "roster.csv").write_text(
        "id,folder,name,email,sis_id,tutor\n"
        "alice,class/alice,Alice Doe,alice@uni.example,S1,Kim\n"
        '"bob, jr",class/bob.zip,"Doe, Bob",bob@uni.example,S2,Lee\n'
    )
    return path


def export(grades: Path, form: str) -> list[dict[str, str]]:
    out = grades.parent / "out" / f"{form}.csv"
    roster = ["--roster", str(grades.parent / "roster.csv")]
    assert main(["export", str(grades), *roster, "--format", form, "--out", str(out)]) == 0
    return list(csv.DictReader(out.open(encoding="utf-8")))


def test_moodle_rows_are_students_with_email_id_number_and_how_the_total_was_made(grades):
    rows = export(grades, "moodle")
    assert [(r["Email address"], r["ID number"], r["msdlab"]) for r in rows] == [
        ("alice@uni.example", "S1", "33"),
        ("bob@uni.example", "S2", "13.5"),
    ]
    assert rows[1]["Feedback"] == "checks 15, late penalty 1.5; total 13.5"


def test_plain_csv_keeps_the_roster_columns_max_points_and_relative_sources(grades):
    rows = export(grades, "csv")
    assert [r["id"] for r in rows] == ["alice", "bob, jr"]  # no summary row
    assert rows[0]["tutor"] == "Kim" and rows[0]["max_points"] == "95"
    assert rows[0]["adjustment"] == "-2" and rows[1]["late_penalty"] == "1.5"
    assert rows[0]["source"] == "../class/alice/assignments"
    assert rows[1]["source"] == "../class/bob.zip"


def test_a_student_missing_either_side_is_named(grades, capsys):
    roster = grades.parent / "roster.csv"
    roster.write_text(roster.read_text() + "carol,class/carol,Carol Doe,c@uni.example,,Kim\n")
    rows = export(grades, "canvas")
    assert rows[0]["Student"] == "    Points Possible" and rows[3]["msdlab"] == ""
    warned = capsys.readouterr().err
    assert "'carol' is in the roster but not in" in warned
    assert "'carol' has none of canvas_id, sis_id, sis_login_id in the roster" in warned


def test_a_roster_without_a_header_and_canvas_without_a_roster_are_refused(grades, capsys):
    roster = grades.parent / "roster.csv"
    roster.write_text("alice,class/alice\n")
    out = ["--out", str(grades.parent / "x.csv")]
    assert main(["export", str(grades), "--roster", str(roster), "--format", "csv", *out]) == 2
    assert "first line must name the columns" in capsys.readouterr().err
    assert main(["export", str(grades), "--format", "canvas", *out]) == 2
    assert "--format canvas needs --roster FILE" in capsys.readouterr().err


def test_a_change_written_after_the_last_grading_run_is_in_the_export(grades):
    with (grades.parent / "grades.adjustments.csv").open("a") as handle:
        handle.write('"bob, jr",2,=20,"checked by hand: right, but printed in mm"\n')
    rows = export(grades, "moodle")
    # bob: 15 + 20 points, less the late penalty as charged (msdlab grade --due charges
    # it again on the new points)
    assert [r["msdlab"] for r in rows] == ["33", "33.5"]
    assert rows[1]["Feedback"] == "checks 15, late penalty 1.5, adjustment 20; total 33.5"
    assert "asked by email" not in (grades.parent / "out" / "moodle.csv").read_text()


@pytest.mark.parametrize(
    ("line", "says"),
    [
        ("alice,1,=900,typo\n", "line 3: task1 is worth 15 points; this line sets it to 900"),
        ("alice,,-2,report handed in late\n", "line 3: repeats line 2 (the same change and reason"),
        ("carol,,+1,x\n", None),  # no such student: a warning, the export goes on
    ],
)
def test_a_mistake_in_the_changes_stops_the_export_as_it_stops_grading(grades, capsys, line,
                                                                       says):  # fmt: skip
    with (grades.parent / "grades.adjustments.csv").open("a") as handle:
        handle.write(line)
    out = grades.parent / "out" / "canvas.csv"
    arguments = ["export", str(grades), "--format", "csv", "--out", str(out)]
    status = main(arguments)
    printed = capsys.readouterr().err
    if says is None:
        assert status == 0 and "warning:" in printed and "'carol'" in printed
    else:
        assert status == 2 and says in printed and not out.exists()


def _graded(identifier: str, passed: int) -> gradebook_db.Result:
    """A graded submission of two 5-point checks of task 1, ``passed`` of them passed."""
    checks = [
        CheckResult(f"t::c{n}", f"c{n}", 1, 5, False, "passed" if n < passed else "failed")
        for n in range(2)
    ]
    report = CheckReport(identifier, checks)
    return gradebook_db.Result(identifier, f"/class/{identifier}", "graded", [], report, "f")


@pytest.fixture
def gradebook(tmp_path: Path) -> Path:
    """A class in the gradebook, its grades file rendered, then a student graded again and a
    late one committed by a run stopped before it rendered (the grades file is behind)."""
    out = tmp_path / "grades.csv"
    connection = gradebook_db.connect(gradebook_db.beside(out))
    try:
        for identifier, passed in (("alice", 2), ("bob", 0)):
            gradebook_db.record(connection, _graded(identifier, passed), None)
        render.render(connection, out, Terms())
        gradebook_db.record(connection, _graded("bob", 1), None)
        gradebook_db.record(connection, _graded("carol", 2), None)
    finally:
        connection.close()
    (tmp_path / "grades.adjustments.csv").write_text(
        "id,task,change,reason\nalice,,-1,late report\n"
    )
    return out


def test_the_export_reads_the_gradebook_not_a_grades_file_left_behind(gradebook):
    assert {row["id"]: row["total"] for row in export_plain(gradebook)} == {
        "alice": "9", "bob": "5", "carol": "10",
    }  # fmt: skip
    assert {row["id"]: row["total"] for row in csv.DictReader(gradebook.open())} == {
        "(max points)": "10", "alice": "10", "bob": "0",
    }  # fmt: skip


def test_the_gradebook_and_the_grades_file_rendered_from_it_export_the_same(gradebook):
    assert main(["grade", "--out", str(gradebook), "--render"]) == 0
    from_database = export_plain(gradebook)
    gradebook_db.beside(gradebook).unlink()  # a course graded before the gradebook
    assert export_plain(gradebook) == from_database


def test_the_gradebook_may_be_named_and_a_missing_one_is_named(gradebook, capsys):
    out = ["--format", "csv", "--out", str(gradebook.parent / "x.csv")]
    assert main(["export", str(gradebook_db.beside(gradebook)), *out]) == 0
    gradebook_db.beside(gradebook).unlink()
    gradebook.unlink()
    assert main(["export", str(gradebook), *out]) == 2
    said = capsys.readouterr().err
    assert f"no grades at {gradebook} nor a gradebook {gradebook_db.beside(gradebook)}" in said


def test_a_planted_file_in_the_gradebook_s_place_is_refused_by_name(gradebook, capsys):
    gradebook_db.beside(gradebook).write_text("id,total\nalice,95\n")
    out = ["--format", "csv", "--out", str(gradebook.parent / "x.csv")]
    assert main(["export", str(gradebook), *out]) == 2
    assert "grades.db is not a gradebook msdlab can read" in capsys.readouterr().err
    assert not (gradebook.parent / "x.csv").exists()


def export_plain(grades: Path) -> list[dict[str, str]]:
    out = grades.parent / "out" / "plain.csv"
    assert main(["export", str(grades), "--format", "csv", "--out", str(out)]) == 0
    return list(csv.DictReader(out.open(encoding="utf-8")))
