"""Due dates and late work: the policy's arithmetic, due dates in time zones, extensions."""

from __future__ import annotations

import re
from datetime import datetime, timedelta, timezone
from fractions import Fraction

import pytest
from hypothesis import given
from hypothesis import strategies as st

from msdlab.cli import main
from msdlab.instructor import intake
from msdlab.instructor.judging.grading import Grade
from msdlab.instructor.points import gradebook
from msdlab.instructor.rules.late import (
    LatePolicy,
    format_points,
    parse_due,
    read_extensions,
    time_zone,
)
from msdlab.instructor.rules.problems import InstructorFileError

POLICY = LatePolicy.parse("grace=15m,penalty=10%/day,cap=50%,cutoff=7d")
points = st.fractions(min_value=0, max_value=100, max_denominator=4)
lateness = st.timedeltas(min_value=timedelta(days=-3), max_value=timedelta(days=10))


def test_a_worked_example_of_each_part():
    earned = Fraction(17)
    assert POLICY.charge(earned, timedelta(minutes=-5)).penalty == 0
    within = POLICY.charge(earned, timedelta(minutes=14))
    assert within.penalty == 0 and "grace" in within.reason
    # counted from the due date: 16 minutes late is one started day
    assert POLICY.charge(earned, timedelta(minutes=16)).penalty == Fraction(17, 10)
    two_days = POLICY.charge(earned, timedelta(days=1, hours=1))
    assert two_days.penalty == Fraction(34, 10)
    assert two_days.reason.endswith("2 started days × 10% of 17 points = 3.4 points")
    capped = POLICY.charge(earned, timedelta(days=6))
    assert capped.penalty == Fraction(17, 2) and "capped at 50%" in capped.reason
    refused = POLICY.charge(earned, timedelta(days=7, seconds=1))
    assert refused.penalty == earned and not refused.accepted and "cutoff" in refused.reason


def test_points_per_hour_and_a_cap_in_points():
    policy = LatePolicy.parse("penalty=2/hour, cap=5")
    assert policy.charge(Fraction(20), timedelta(hours=1, minutes=1)).penalty == 4
    assert policy.charge(Fraction(20), timedelta(hours=9)).penalty == 5
    assert policy.charge(Fraction(3), timedelta(hours=9)).penalty == 3  # never below zero


@given(points, lateness)
def test_the_penalty_is_between_nothing_and_the_points_earned(earned, late):
    charged = POLICY.charge(earned, late)
    assert 0 <= charged.penalty <= earned
    if charged.accepted:
        assert charged.penalty <= earned / 2  # the cap
    if late <= timedelta(minutes=15):
        assert charged.penalty == 0


@given(points, lateness, lateness)
def test_later_never_costs_less(earned, one, other):
    early, late = sorted((one, other))
    assert POLICY.charge(earned, early).penalty <= POLICY.charge(earned, late).penalty


@given(points, st.integers(min_value=1, max_value=4))
def test_each_started_day_costs_the_same(earned, days):
    policy = LatePolicy.parse("penalty=10%/day")
    start = policy.charge(earned, timedelta(days=days - 1, seconds=1)).penalty
    end = policy.charge(earned, timedelta(days=days)).penalty
    assert start == end == min(earned, days * earned / 10)


@pytest.mark.parametrize(
    ("policy", "says"),
    [
        ("penalty=10%", "say per what"),
        ("grace=15", "duration like 15m"),
        ("cap=half", "percentage like 10%"),
        ("late=1d", "unknown part 'late=1d'"),
        ("grace=99999999999d", "grace=99999999999d is longer than a term can use: at most 366d"),
        ("grace=15m,penalty=10%/day,grace=1h", "grace is given twice; keep one grace=..."),
        ("penalty=150%/day", "penalty=150%: more than all the points; at most 100%"),
        ("cap=50,cap=20%,cutoff=1x", "cap is given twice"),
    ],
)
def test_a_policy_written_wrong_says_how_to_write_it(policy, says):
    with pytest.raises(ValueError, match=re.escape(says)):
        LatePolicy.parse(policy)


def test_every_mistake_of_a_policy_is_named_at_once():
    with pytest.raises(InstructorFileError) as refused:
        LatePolicy.parse("cap=50,cap=20%,cutoff=1x")
    assert [problem.where for problem in refused.value.problems] == ["--late-policy"] * 2
    assert "2 mistakes in the instructor's files" in str(refused.value)


def test_a_due_date_without_offset_is_wall_clock_time_in_the_course_zone():
    berlin = time_zone("Europe/Berlin")
    winter = parse_due("2027-03-01T23:59", berlin)
    summer = parse_due("2027-07-01T23:59", berlin)
    assert winter.utcoffset() == timedelta(hours=1) and summer.utcoffset() == timedelta(hours=2)
    utc = datetime(2027, 3, 1, 23, 59, tzinfo=timezone.utc)
    assert parse_due("2027-03-01T23:59Z", berlin) == utc
    assert parse_due("2027-03-01T23:59+05:30", None).utcoffset() == timedelta(hours=5, minutes=30)


def test_the_machine_zone_is_the_default(monkeypatch):
    import time

    monkeypatch.setenv("TZ", "America/New_York")
    time.tzset()
    try:
        assert parse_due("2027-03-01T23:59", None).utcoffset() == timedelta(hours=-5)
        assert parse_due("2027-07-01T23:59", None).utcoffset() == timedelta(hours=-4)
    finally:
        monkeypatch.undo()
        time.tzset()


@pytest.mark.parametrize(
    ("text", "says"), [("2027-03-01", "no time of day"), ("next friday", "like 2027-03-01T23:59")]
)
def test_a_due_date_written_wrong_says_how_to_write_it(text, says):
    with pytest.raises(ValueError, match=says):
        parse_due(text, None)


def test_an_unknown_zone_is_named():
    with pytest.raises(ValueError, match="'Mars/Olympus' is not a time zone"):
        time_zone("Mars/Olympus")


def test_extensions_add_a_duration_or_give_a_date(tmp_path):
    due = parse_due("2027-03-01T23:59", timezone.utc)
    path = tmp_path / "extensions.csv"
    path.write_text("id,extension,due,reason\nalice,2d,,illness\nbob,,2027-03-05T12:00,travel\n")
    own, problems = read_extensions(path, due, timezone.utc)
    assert problems == []
    assert own == {
        "alice": due + timedelta(days=2),
        "bob": datetime(2027, 3, 5, 12, tzinfo=timezone.utc),
    }
    path.write_text("alice,2d\n")
    (problem,) = read_extensions(path, due, timezone.utc)[1]
    assert "line 1: the first line must name the columns" in str(problem)
    path.write_text("id,extension\nalice,two days\n")
    (problem,) = read_extensions(path, due, timezone.utc)[1]
    assert "line 2: extension='two days'" in str(problem)


@pytest.mark.parametrize(
    ("lines", "says"),
    [
        ("alice,2d,illness\nalice,3d,again\n", "line 3: 'alice' has a second extension (the "
         "first is on line 2); keep one line per student"),
        ("alice,2d,ill, then away\n", "line 2: more fields than the first line names columns "
         "(left over: then away)"),
        (",2d,illness\n", "line 2: no student id"),
        ("alice,99999999999d,x\n", "line 2: extension=99999999999d is longer than a term can "
         "use: at most 366d"),
    ],
)  # fmt: skip
def test_extension_mistakes_are_named_with_their_line(tmp_path, lines, says):
    path = tmp_path / "extensions.csv"
    path.write_text("id,extension,reason\n" + lines)
    problems = read_extensions(path, parse_due("2027-03-01T23:59Z", None), timezone.utc)[1]
    assert [says in str(problem) for problem in problems] == [True], problems
    assert all(problem.refused for problem in problems)


def test_an_extension_and_a_due_date_on_one_line_is_refused(tmp_path):
    path = tmp_path / "extensions.csv"
    path.write_text("id,extension,due\nalice,2d,2027-03-05T12:00\nbob,,2027-03-05T12:00\n")
    own, (problem,) = read_extensions(path, parse_due("2027-03-01T23:59Z", None), timezone.utc)
    assert "line 2: both an extension (2d) and a due date (2027-03-05T12:00); give one" in str(
        problem
    )
    assert list(own) == ["bob"]


@pytest.mark.parametrize(
    ("text", "says"),
    [
        ("2027-03-28T02:30", "2027-03-28T02:30 does not exist on the clock of Europe/Berlin "
         "(daylight saving time); write the one you mean with its offset: "
         "2027-03-28T01:30+01:00 or 2027-03-28T03:30+02:00"),
        ("2027-10-31T02:30", "2027-10-31T02:30 happens twice on the clock of Europe/Berlin "
         "(daylight saving time); write the one you mean with its offset: "
         "2027-10-31T02:30+02:00 or 2027-10-31T02:30+01:00"),
    ],
)  # fmt: skip
def test_a_due_time_the_clock_skips_or_shows_twice_is_refused_with_its_candidates(text, says):
    with pytest.raises(ValueError) as refused:
        parse_due(text, time_zone("Europe/Berlin"))
    assert str(refused.value) == f"--due {says}"
    written = says.rsplit(": ", 1)[1].split(" or ")
    instants = {parse_due(candidate, None) for candidate in written}
    assert len(instants) == 2  # each candidate is an instant of its own, and reads back


def test_a_due_time_the_machine_clock_skips_is_refused(monkeypatch):
    import time

    monkeypatch.setenv("TZ", "America/New_York")
    time.tzset()
    try:
        with pytest.raises(ValueError, match="does not exist on this machine's clock"):
            parse_due("2027-03-14T02:30", None)
        with pytest.raises(ValueError, match="happens twice on this machine's clock"):
            parse_due("2027-11-07T01:30", None)
        assert parse_due("2027-03-14T03:30", None).utcoffset() == timedelta(hours=-4)
    finally:
        monkeypatch.undo()
        time.tzset()


@pytest.mark.parametrize(
    ("value", "text"),
    [
        (Fraction(7), "7"),
        (Fraction(15, 2), "7.5"),
        (Fraction(20, 3), "6.67"),
        (-Fraction(17), "-17"),
    ],
)
def test_points_are_short_decimals(value, text):
    assert format_points(value) == text


def test_the_grade_command_explains_its_late_options(capsys):
    with pytest.raises(SystemExit) as leaving:
        main(["grade", "--help"])
    assert leaving.value.code == 0
    assert "grace=15m,penalty=10%/day,cap=50%,cutoff=7d" in capsys.readouterr().out


@pytest.mark.parametrize(
    ("options", "says"),
    [
        (["--due", "2027-03-01"], "--due '2027-03-01' has no time of day"),
        (["--late-policy", "penalty=10%/day"], "--late-policy and --extensions need --due DATE"),
        (["--due", "2027-03-01T23:59", "--timezone", "CET+1"], "is not a time zone"),
    ],
)
def test_bad_late_options_stop_the_run_before_grading(tmp_path, capsys, options, says):
    (tmp_path / "alice").mkdir()
    given = [str(tmp_path / "alice"), "--out", str(tmp_path / "grades.csv"), *options]
    assert main(["grade", *given]) == 2
    printed = capsys.readouterr()
    assert says in printed.err and "grading" not in printed.err


def test_every_mistake_in_the_instructors_files_stops_grading_before_it_starts(tmp_path, capsys):
    alice = tmp_path / "class" / "alice"
    alice.mkdir(parents=True)
    (alice / "task1.py").write_text("")
    (tmp_path / "extensions.csv").write_text(
        "id,extension,due\nalice,2d,2027-03-05T12:00\nalice,,2027-03-28T02:30\n"
    )
    (tmp_path / "grades.adjustments.csv").write_text(
        "id,task,change,reason\nalice,1,=900,typo\nalice,2,+1,twice\nalice,2,+1,twice\n"
    )
    extensions = str(tmp_path / "extensions.csv")
    options = ["--due", "2027-03-01T23:59", "--timezone", "Europe/Berlin", "--late-policy",
               "grace=99999999999d,grace=1h", "--extensions", extensions]  # fmt: skip
    out = tmp_path / "grades.csv"
    assert main(["grade", str(alice), "--out", str(out), *options]) == 2
    printed = capsys.readouterr().err
    said = [
        "6 mistakes in the instructor's files; fix and run again",
        "--late-policy: grace=99999999999d is longer than a term can use",
        "--late-policy: grace is given twice",
        "extensions.csv, line 2: both an extension (2d) and a due date",
        "extensions.csv, line 3: 'alice' has a second extension (the first is on line 2)",
        "grades.adjustments.csv, line 2: task1 is worth 15 points; this line sets it to 900",
        "grades.adjustments.csv, line 4: repeats line 3",
    ]
    assert [line for line in said if line not in printed] == []
    assert "grading 1 submission" not in printed and not out.exists()


def test_regrading_a_late_student_without_the_due_date_is_refused_before_grading(tmp_path, capsys):
    alice = tmp_path / "alice"
    alice.mkdir()
    (alice / "task1.py").write_text("")
    book = gradebook.Gradebook()
    book.record(Grade("alice", None, []), intake.Entry("alice", alice, alice), None, False)
    book.rows["alice"].update(due="2027-03-01T23:59+01:00", late_penalty="2")
    out = tmp_path / "grades.csv"
    book.write(out)
    assert main(["grade", str(alice), "--out", str(out)]) == 2
    printed = capsys.readouterr().err
    assert "row 'alice': was graded against the due date 2027-03-01T23:59+01:00" in printed
    assert "give --due (and --late-policy, --extensions) as in that run" in printed
    assert "grading 1 submission" not in printed
