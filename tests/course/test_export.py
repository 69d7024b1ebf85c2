"""``msdlab export``: the grades as Canvas, Moodle and plain CSV files, read back."""

from __future__ import annotations

import csv
from pathlib import Path

import pytest

from msdlab.cli import main

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
