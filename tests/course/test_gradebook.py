"""The gradebook database: whole records, views rendered from it, writers side by side,
an older grades file taken in, and the sandbox user locks seen by every run."""

from __future__ import annotations

import csv
import multiprocessing
import os
import subprocess
import sys
import textwrap
from pathlib import Path

import pytest

from msdlab.cli import main
from msdlab.course.report import CheckReport, CheckResult
from msdlab.instructor.judging import grading
from msdlab.instructor.outputs import csv_files, render
from msdlab.instructor.points import gradebook, gradebook_db
from msdlab.instructor.rules.final_points import Terms

CHECKS = [
    CheckResult(
        "t::a",
        "rest_state",
        2,
        2,
        False,
        "failed",
        "CheckFailed",
        "net force 0.5",
        mistake="gravity's sign",
    ),
    CheckResult("t::b", "pulls", 2, 3, False, "passed"),
    CheckResult("t::c", "secret", 2, 2, True, "passed"),
]


def result(identifier: str, status: str = gradebook_db.GRADED) -> gradebook_db.Result:
    report = CheckReport(identifier, list(CHECKS)) if status == gradebook_db.GRADED else None
    return gradebook_db.Result(identifier, f"/class/{identifier}", status, ["a note"], report,
                               "f1", "2027-03-01T12:00:00+00:00", "git commit")  # fmt: skip


def rows_of(path: Path) -> dict[str, dict[str, str]]:
    return {row["id"]: row for row in csv.DictReader(path.open(encoding="utf-8"))}


def test_a_result_is_read_back_whole(tmp_path):
    connection = gradebook_db.connect(tmp_path / "grades.db")
    gradebook_db.record(connection, result("alice"), gradebook_db.start_run(connection, ["x"]))
    gradebook_db.record(connection, result("bob", gradebook_db.GRADER_FAILED), None)
    alice, bob = gradebook_db.read_class(tmp_path / "grades.csv")
    assert alice.checks == CHECKS and alice.tasks[2] == ("5", "7") and alice.tasks[1] == ("0", "0")
    assert (alice.handed_in, alice.handed_in_from, alice.notes) == (
        "2027-03-01T12:00:00+00:00", "git commit", ["a note"],
    )  # fmt: skip
    assert bob.status == "grader failed" and bob.fingerprint is None and bob.checks == []
    assert gradebook_db.statuses(connection) == {"alice": ("graded", "f1"),
                                                 "bob": ("grader failed", None)}  # fmt: skip


def test_a_file_that_is_not_a_gradebook_is_refused_by_name(tmp_path):
    (tmp_path / "grades.db").write_text("id,total\nalice,3\n")
    with pytest.raises(ValueError, match=r"grades.db is not a gradebook msdlab can read"):
        gradebook_db.connect(tmp_path / "grades.db")


def test_the_views_cover_the_whole_class_and_can_be_rendered_again(tmp_path):
    connection = gradebook_db.connect(tmp_path / "grades.db")
    for identifier in ("alice", "bob"):
        gradebook_db.record(connection, result(identifier), None)
    absent = gradebook_db.Result("carol", "carol", gradebook_db.ABSENT, ["nothing handed in"])
    gradebook_db.record(connection, absent, None)
    gradebook_db.record(connection, result("dave", gradebook_db.GRADER_FAILED), None)
    out, notes = tmp_path / "grades.csv", tmp_path / "feedback"
    render.render(connection, out, Terms(), notes)
    rows = rows_of(out)
    assert set(rows) == {"(max points)", "alice", "bob", "carol", "dave"}
    assert rows["alice"]["task2"] == rows["alice"]["total"] == "5" and rows["carol"]["total"] == "0"
    assert rows["(max points)"]["total"] == "7"
    assert sorted(p.name for p in (notes / "students").iterdir()) == ["alice.md", "bob.md",
                                                                      "carol.md"]  # fmt: skip
    summary = (notes / "summary.md").read_text()
    assert "2 of 4 submissions graded" in summary and "Nothing handed in (1): carol" in summary
    assert "Could not be graded, the grader's failure and not the students' (1): dave" in summary
    out.unlink()
    (notes / "students" / "bob.md").unlink()
    assert main(["grade", "--out", str(out), "--render", "--feedback", str(notes)]) == 0
    assert rows_of(out) == rows and (notes / "students" / "bob.md").is_file()


def test_an_older_grades_file_and_its_adjustments_are_taken_in(tmp_path, capsys):
    out = tmp_path / "grades.csv"
    book = gradebook.Gradebook()
    book.maximum.update({f"task{t}": "10" for t in range(1, 6)} | {"total": "50"})
    book.rows["alice"] = {"id": "alice", "source": "class/alice", "task1": "7", "points": "7",
                          "total": "7", "notes": "", "fingerprint": "abc"}  # fmt: skip
    book.rows["=bob"] = {"id": "=bob", "source": "class/bob", "task1": "0", "total": "0",
                         "notes": "task1: not attempted", "fingerprint": ""}  # fmt: skip
    book.write(out)
    (tmp_path / "grades.adjustments.csv").write_text("id,task,change,reason\nalice,1,+2,by hand\n")
    assert main(["grade", "--out", str(out), "--render"]) == 0
    assert "took 2 rows of" in capsys.readouterr().err
    rows = rows_of(out)
    assert rows["alice"]["total"] == "9" and rows["alice"]["adjustment"] == "2"
    assert csv_files.restored(next(i for i in rows if "bob" in i)) == "=bob"
    alice, bob = sorted(gradebook_db.read_class(out), key=lambda r: r.id != "alice")
    assert (alice.status, alice.fingerprint, bob.status) == ("graded", "abc", "not graded")
    assert main(["grade", "--out", str(out), "--render"]) == 0  # taken in once only
    assert "took" not in capsys.readouterr().err and rows_of(out) == rows


def _write_many(path: str, prefix: str, count: int) -> None:
    connection = gradebook_db.connect(Path(path).with_suffix(".db"))
    for number in range(count):
        gradebook_db.record(connection, result(f"{prefix}{number:02}"), None)
        render.render(connection, Path(path), Terms())


def test_two_runs_writing_one_gradebook_lose_no_row(tmp_path):
    out = tmp_path / "grades.csv"
    context = multiprocessing.get_context("spawn")
    writers = [context.Process(target=_write_many, args=(str(out), p, 25)) for p in "ab"]
    for writer in writers:
        writer.start()
    for writer in writers:
        writer.join(120)
        assert writer.exitcode == 0
    rows = rows_of(out)
    assert len(rows) == 51 and all(
        rows[f"{p}{n:02}"]["total"] == "5" for p in "ab" for n in range(25)
    )


HOLD = textwrap.dedent("""
    import sys
    from msdlab.instructor.judging import grading
    with grading.reserved_uids(1) as uids:
        print(uids[0], flush=True)
        sys.stdin.read()
""")


@pytest.mark.skipif(os.geteuid() != 0, reason="sandbox user ids are reserved only as root")
def test_runs_with_different_temporary_folders_never_share_a_sandbox_user(tmp_path):
    holders = []
    for name in ("one", "two"):
        (tmp_path / name).mkdir()
        environment = dict(os.environ, TMPDIR=str(tmp_path / name))
        pipes = {"stdin": subprocess.PIPE, "stdout": subprocess.PIPE, "text": True}
        holders.append(subprocess.Popen([sys.executable, "-c", HOLD], env=environment, **pipes))
    try:
        uids = [int(holder.stdout.readline()) for holder in holders]
    finally:
        for holder in holders:
            holder.communicate("", timeout=30)
    assert uids[0] != uids[1] and min(uids) >= grading.FIRST_UID
    assert grading.lock_folder() in {folder for folder in grading.LOCK_FOLDERS}
