"""Manual changes and late penalties settled into each row: the arithmetic, the file,
and what the feedback says. (A grading run that keeps them: test_term_runs.py.)"""

from __future__ import annotations

import re
import shutil
from datetime import datetime, timedelta, timezone
from fractions import Fraction

import pytest
from hypothesis import given
from hypothesis import strategies as st

from msdlab.cli import main
from msdlab.course import PROJECT_ROOT
from msdlab.instructor.intake import HandIn
from msdlab.instructor.rules import adjustments, final_points
from msdlab.instructor.rules.final_points import Terms
from msdlab.instructor.rules.late import LatePolicy

DUE = datetime(2027, 3, 1, 23, 59, tzinfo=timezone.utc)
NUMBERS = ("points", "late_penalty", "adjustment", "total")


def row(*tasks: int) -> dict[str, str]:
    return {"id": "alice", **{f"task{t}": str(p) for t, p in enumerate(tasks, start=1)},
            "points": str(sum(tasks)), "total": str(sum(tasks))}  # fmt: skip


def changes(tmp_path, text: str) -> dict[str, list[adjustments.Change]]:
    path = tmp_path / "grades.adjustments.csv"
    path.write_text("id,task,change,reason\n" + text)
    return adjustments.read(path)


def test_task_changes_come_before_the_penalty_and_total_changes_after(tmp_path):
    made = changes(tmp_path, "alice,2,=10,checked by hand\nalice,total,+1,report\n")
    late = HandIn(datetime(2027, 3, 2, 1, tzinfo=timezone.utc), "zip entry times", "student")
    terms = Terms(DUE, LatePolicy.parse("penalty=10%/day"), {}, {"alice": late}, made)
    rows = {"alice": row(10, 0, 0, 0, 0)}
    lines = final_points.settle(rows, terms)["alice"]
    settled = rows["alice"]
    # (10 + 10) points after the override, 10% of 20 taken, then +1
    assert settled["late_penalty"] == "2" and settled["total"] == "19"
    assert settled["adjustment"] == "11" and settled["points"] == "10"
    assert settled["handed_in"] == "2027-03-02T01:00:00+00:00"
    assert lines[0] == "- task 2 set to 10 points: checked by hand"
    assert lines[1] == "- total +1 point: report"
    assert "1 started day × 10% of 20 points = 2 points" in lines[2]
    section = final_points.feedback_section(settled, lines, "95")
    assert "**Total: 19 of 95 points** (checks 10 − late penalty 2 + adjustment 11)" in section


def test_an_extension_moves_the_due_date_and_is_named(tmp_path):
    late = HandIn(datetime(2027, 3, 2, 1, tzinfo=timezone.utc), "file modification time", "student")
    terms = Terms(DUE, LatePolicy.parse("penalty=10%/day"), {"alice": DUE.replace(day=3)},
                  {"alice": late})  # fmt: skip
    rows = {"alice": row(10)}
    lines = final_points.settle(rows, terms)["alice"]
    assert rows["alice"]["late_penalty"] == "" and rows["alice"]["total"] == "10"
    assert "(your extension)" in lines[0] and "on time" in lines[0]


def test_a_run_without_a_due_date_keeps_earlier_penalties():
    rows = {"alice": {**row(10), "late_penalty": "1.5", "late": "handed in late: 1.5 points"}}
    final_points.settle(rows, Terms())
    assert rows["alice"]["total"] == "8.5" and rows["alice"]["adjustment"] == ""


def test_refreshing_feedback_replaces_the_section(tmp_path):
    for kind in ("students", "instructor"):
        (tmp_path / kind).mkdir()
        (tmp_path / kind / "alice.md").write_text("# Feedback: alice\n\nchecks...\n")
    rows = {"alice": row(10)}
    for reason in ("first reason", "second reason"):
        made = changes(tmp_path, f"alice,,+2,{reason}\n")
        lines = final_points.settle(rows, Terms(changes=made))
        final_points.refresh_feedback(tmp_path, rows, lines, "95")
    for kind in ("students", "instructor"):
        text = (tmp_path / kind / "alice.md").read_text()
        assert text.count(final_points.MARK) == 1 and "second reason" in text
        assert "first reason" not in text and text.startswith("# Feedback: alice\n\nchecks...")
    final_points.refresh_feedback(tmp_path, rows, final_points.settle(rows, Terms()), "95")
    assert (tmp_path / "students" / "alice.md").read_text() == "# Feedback: alice\n\nchecks...\n"


def test_the_section_comes_right_below_the_points_the_checks_gave():
    student = "# Feedback: a\n\n**10 of 95 points**: public checks 4 of 60.\n\n## Task 1\n"
    teacher = "# a\n\nHanded in: `x`\n\n10/95 points (task1 10), graded in 2.0 s\n\nNote: x\n"
    for text, headline, rest in (
        (student, "public checks 4 of 60.\n", "## Task 1\n"),
        (teacher, "in 2.0 s\n", "Note: x\n"),
    ):
        section = "<!-- msdlab: late work and manual changes -->\nTotal 12\n" + final_points.END
        once = final_points.with_section(text, section + "\n")
        assert once.count("Total 12") == 1
        assert once.index(headline) < once.index("Total 12") and once.endswith(rest)
        assert final_points.with_section(once, section + "\n") == once
        assert final_points.with_section(once, "") == text


@pytest.mark.parametrize(
    ("line", "says"),
    [
        ("alice,7,+1,x\n", "task '7' is not one of"),
        ("alice,2,plus one,x\n", "like +1, -2.5 or =4"),
        ("alice,2,+1,\n", "give the reason"),
        (",2,+1,x\n", "no student id"),
    ],
)
def test_a_change_written_wrong_names_its_line(tmp_path, line, says):
    with pytest.raises(ValueError, match=f"line 2: .*{re.escape(says)}"):
        changes(tmp_path, line)


def test_the_file_lies_beside_the_grades(tmp_path):
    assert adjustments.beside(tmp_path / "grades.csv") == tmp_path / "grades.adjustments.csv"
    assert adjustments.read(tmp_path / "none.csv") == {}


change = st.builds(
    adjustments.Change,
    id=st.just("alice"),
    task=st.sampled_from([None, 1, 2]),
    value=st.fractions(min_value=-5, max_value=20, max_denominator=2),
    sets=st.booleans(),
    reason=st.just("because"),
)


@given(st.lists(change, max_size=4), st.integers(min_value=-48, max_value=200))
def test_the_total_is_always_points_minus_penalty_plus_adjustment(made, hours_late):
    handed = HandIn(DUE + timedelta(hours=hours_late), "zip entry times", "student")
    policy = LatePolicy.parse("penalty=10%/day,cap=50%,cutoff=7d")
    rows = {"alice": row(10, 4, 0, 0, 0)}
    final_points.settle(rows, Terms(DUE, policy, {}, {"alice": handed}, {"alice": made}))
    settled = {k: Fraction(v or 0) for k, v in rows["alice"].items() if k in NUMBERS}
    made_total = settled["points"] - settled["late_penalty"] + settled["adjustment"]
    assert settled["total"] == made_total  # exactly, as the CSV shows them
    assert settled["late_penalty"] >= 0
    if not made:
        assert rows["alice"]["adjustment"] == "" and settled["total"] <= 14


WORTH = {**{f"task{t}": Fraction(p) for t, p in zip(range(1, 6), (15, 20, 20, 15, 25))},
         "total": Fraction(95)}  # fmt: skip


def mistakes(tmp_path, text: str, known=("alice", "bob"), header="id,task,change,reason,note"):
    """The problems of an adjustments file holding ``text`` below ``header``."""
    path = tmp_path / "grades.adjustments.csv"
    path.write_text(header + "\n" + text)
    made, found = adjustments.parse(path)
    found += adjustments.problems(made, str(path))
    return [*found, *adjustments.against_class(made, str(path), WORTH, set(known))]


@pytest.mark.parametrize(
    ("text", "says"),
    [
        ("alice,1,=900,typo\n", "line 2: task1 is worth 15 points; this line sets it to 900; "
         "write a change within 0 ... 15"),
        ("alice,,+96,typo\n", "line 2: total is worth 95 points; this line changes it by 96"),
        ("alice,2,+1,checked\nbob,1,=3,x\nalice,2,+1,checked\n",
         "line 4: repeats line 2 (the same change and reason: it would count twice); delete "
         "one; to add twice, write the sum once"),
        ("alice,2,+1,checked, the sign was right\n", "line 2: a note starting with a space, "
         "the end of the reason? (left over: the sign was right); a comma inside a reason or "
         "note must be in double quotes"),
        ("alice,2,+1,checked, the sign, was right\n", "line 2: more fields than the first line "
         "names columns (left over: was right)"),
        ("alice,2,+1,checked\nalice,2,=4,by hand\n", "line 2: line 3 sets alice's task2 later, "
         "so this change would count for nothing"),
        ("Alice,2,+1,checked\n", "line 2: no submission has the id 'Alice'; did you mean "
         "'alice'?"),
    ],
)  # fmt: skip
def test_each_mistake_of_the_changes_is_refused_with_its_line_and_fix(tmp_path, text, says):
    found = mistakes(tmp_path, text)
    assert [str(problem) for problem in found if says in str(problem)], found
    assert len(found) == 1 and found[0].refused


def test_a_change_for_a_student_not_graded_yet_is_a_warning(tmp_path):
    (found,) = mistakes(tmp_path, "carol,2,+1,checked\n")
    assert not found.refused and "no submission has the id 'carol'" in str(found)


def test_the_header_names_the_columns_and_the_private_note(tmp_path):
    (found,) = mistakes(tmp_path, "alice,2,+1,x,y\n", header="id,task,change,reason,comment")
    assert "line 1: the first line must be 'id,task,change,reason,note'" in str(found)
    assert mistakes(tmp_path, "alice,2,+1,x\n", header="id,task,change,reason") == []


def test_a_private_note_reaches_the_instructors_feedback_only(tmp_path):
    path = tmp_path / "grades.adjustments.csv"
    path.write_text("id,task,change,reason,note\nalice,1,=0,it is another's work,copied from bob\n")
    made = adjustments.read(path)
    assert str(made["alice"][0]) == "task 1 set to 0 points: it is another's work"
    for kind in ("students", "instructor"):
        (tmp_path / kind).mkdir()
        (tmp_path / kind / "alice.md").write_text("# Feedback: alice\n\n**10 of 95 points**\n")
    rows = {"alice": row(10)}
    lines = final_points.settle(rows, Terms(changes=made))
    private = adjustments.private_notes(made)
    final_points.refresh_feedback(tmp_path, rows, lines, "95", private)
    student = (tmp_path / "students" / "alice.md").read_text()
    teacher = (tmp_path / "instructor" / "alice.md").read_text()
    assert "another's work" in student and "copied from bob" not in student
    assert "private note" in teacher and "copied from bob" in teacher


def test_regrading_a_late_student_without_the_due_date_is_refused():
    rows = {"alice": {**row(10), "due": "2027-03-01T23:59+00:00", "late_penalty": "1"},
            "bob": row(10)}  # fmt: skip
    (found,) = final_points.forgotten_due(rows, ["alice", "bob"], Terms(), "grades.csv")
    assert "grades.csv, row 'alice': was graded against the due date 2027-03-01T23:59" in str(found)
    assert "give --due" in found.fix
    assert final_points.forgotten_due(rows, ["alice"], Terms(due=DUE), "grades.csv") == []


def test_a_lookalike_id_stops_grading_after_the_intake_an_unknown_one_is_warned(tmp_path, capsys):
    (tmp_path / "alice").mkdir()
    (tmp_path / "alice" / "task1.py").write_text("")
    checks = tmp_path / "checks"
    checks.mkdir()
    for name in ("conftest.py", "test_task1.py"):  # task 1's checks: what a change may be
        shutil.copy(PROJECT_ROOT / "tests" / "tasks" / name, checks)
    (tmp_path / "grades.adjustments.csv").write_text(
        "id,task,change,reason,note\nAlice,,+1,report,\nbob,,+1,report,copied\n"
    )
    out = tmp_path / "grades.csv"
    arguments = ["grade", str(tmp_path / "alice"), "--out", str(out), "--checks", str(checks)]
    assert main([*arguments, "--isolation", "process"]) == 2
    printed = capsys.readouterr().err
    assert "line 2: no submission has the id 'Alice'; did you mean 'alice'?" in printed
    assert "warning: " in printed and "line 3: no submission has the id 'bob'" in printed
    assert "grading 1 submission" not in printed and not out.exists()
