"""`msdlab grade --cluster`: the same rows, CSV, feedback and exit status as the local pool,
and a worker killed mid-submission costs a retry, not a row."""

from __future__ import annotations

import csv
import io
import os
import re
import shutil
import signal
import time
from pathlib import Path

import pytest

from msdlab.cli import main
from msdlab.course import PROJECT_ROOT, own_numbers
from msdlab.instructor import intake
from msdlab.instructor.judging import grading
from msdlab.instructor.judging.cluster_grading import grade_all_on_cluster

Client = pytest.importorskip(
    "dask.distributed", reason="needs the extra: pip install -e '.[cluster]'"
).Client

WORKSPACE = re.compile(r"msdlab-grade-\w+")  # each grading's own temporary folder
SECONDS = re.compile(r"\b\d+(\.\d+)? s\b")  # how long a grading took


def comparable(text: str) -> str:
    """Feedback without what differs from run to run: temporary folders and times (the
    class report's name, after the CSV's, is made the same before)."""
    return SECONDS.sub("T s", WORKSPACE.sub("WORKSPACE", text))


def test_cluster_and_local_pool_write_the_same_grades(
    tmp_path: Path, task1_checks: Path, scheduler: str
) -> None:
    shutil.copytree(PROJECT_ROOT / "solutions", tmp_path / "alice")
    (tmp_path / "carol").mkdir()  # nothing handed in
    folders = [str(tmp_path / "alice"), str(tmp_path / "carol")]
    runs = {}
    for label, where in (("pool", ["--jobs", "2"]), ("cluster", ["--cluster", scheduler])):
        out, feedback = tmp_path / f"{label}.csv", tmp_path / f"{label}-feedback"
        status = main(["grade", *folders, "--checks", str(task1_checks), "--out", str(out),
                       "--feedback", str(feedback), "--call-timeout", "10", *where])  # fmt: skip
        report = out.with_suffix(".class.html").name
        named = {path: path.read_text().replace(report, "OUT") for path in feedback.rglob("*.md")}
        files = {str(path.relative_to(feedback)): comparable(text)
                 for path, text in sorted(named.items())}  # fmt: skip
        runs[label] = (status, out.read_text(), files)
    assert runs["cluster"] == runs["pool"]
    status, table, files = runs["pool"]
    rows = {row["id"]: row for row in csv.DictReader(io.StringIO(table))}
    assert rows["alice"]["task1"] == rows[intake.MAX_POINTS_ID]["task1"] != "0"
    assert status == 1 and "no task files" in rows["carol"]["notes"]
    assert {"students/alice.md", "instructor/carol.md", "summary.md"} <= set(files)


def test_a_worker_killed_mid_submission_costs_a_retry(task1_checks: Path, scheduler: str) -> None:
    submission = grading.Submission("alice", PROJECT_ROOT / "solutions")
    with Client(scheduler) as client:
        (worker, pid), = client.run(os.getpid).items()  # fmt: skip
        progress = []
        future = client.submit(grading.grade, submission, task1_checks, call_timeout=10.0)
        deadline = time.monotonic() + 60
        while not client.processing()[worker] and time.monotonic() < deadline:
            time.sleep(0.05)
        time.sleep(1.0)  # into the grading
        os.kill(pid, signal.SIGKILL)
        first = future.result(timeout=120)
        assert list(client.run(os.getpid).values()) != [pid], "the worker was not replaced"
        grades = grade_all_on_cluster(
            [submission], task1_checks, scheduler, progress=lambda *a: progress.append(a),
            call_timeout=10.0,
        )  # fmt: skip
    assert first.graded and first.total == first.report.points > 0, first.notes
    assert [g.total for g in grades] == [first.total] and len(progress) == 1


def test_a_grading_that_fails_in_the_grader_keeps_its_row_in_its_place(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """Whatever happens to one grading, every submission gets its own row, in order."""

    def grade(submission: grading.Submission, checks: Path, **options: object) -> grading.Grade:
        if submission.name == "bob":
            raise MemoryError("the grader ran out of memory")
        return grading.Grade(submission.name, None, ["graded elsewhere"])

    monkeypatch.setattr(grading, "grade", grade)
    names = ["alice", "bob", "carol"]
    submissions = [grading.Submission(name, tmp_path) for name in names]
    seen = []
    grades = grading.grade_all(submissions, tmp_path, progress=lambda g, *_: seen.append(g))
    assert [g.submission for g in grades] == names and sorted(g.submission for g in seen) == names
    assert grades[1].notes == [
        "grader error: the grader lost it (MemoryError: the grader ran out of memory)"
    ]
    assert grades[0].notes == grades[2].notes == ["graded elsewhere"]


def test_on_the_cluster_each_student_is_graded_against_their_own_numbers(
    task1_checks: Path, scheduler: str, tmp_path: Path
) -> None:
    """alice's task 1 in her own template: full marks under her id, the floor step missed
    under carol's (own numbers travel with the grading call to the worker)."""
    solution = (PROJECT_ROOT / "solutions" / "task1.py").read_text()
    folder = tmp_path / "alice"
    folder.mkdir()
    text = own_numbers.personalised(1, solution, own_numbers.numbers("alice"))
    (folder / "task1.py").write_text(text)
    submissions = [grading.Submission(name, folder) for name in ("alice", "carol")]
    alice, carol = grade_all_on_cluster(
        submissions, task1_checks, scheduler, own_numbers=True, call_timeout=10.0,
        isolation="process",
    )  # fmt: skip
    assert alice.graded and alice.points(1) == sum(c.points for c in alice.report.checks)
    failed = {check.name for check in carol.report.checks if not check.passed}
    assert "steps_to_floor_as_template" in failed
