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

from msdlab.analysis.cluster import connect, parse_cluster
from msdlab.cli import main
from msdlab.course import PROJECT_ROOT
from msdlab.instructor import grading, intake
from msdlab.instructor.cluster_grading import grade_all_on_cluster

pytest.importorskip("dask.distributed", reason="needs the extra: pip install -e '.[cluster]'")

WORKSPACE = re.compile(r"msdlab-grade-\w+")  # each grading's own temporary folder
SECONDS = re.compile(r"\b\d+(\.\d+)? s\b")  # how long a grading took


def comparable(text: str) -> str:
    """Feedback without what differs from run to run: temporary folders and times."""
    return SECONDS.sub("T s", WORKSPACE.sub("WORKSPACE", text))


def test_cluster_and_local_pool_write_the_same_grades(tmp_path: Path, task1_checks: Path) -> None:
    shutil.copytree(PROJECT_ROOT / "solutions", tmp_path / "alice")
    (tmp_path / "carol").mkdir()  # nothing handed in
    folders = [str(tmp_path / "alice"), str(tmp_path / "carol")]
    runs = {}
    for label, where in (("pool", ["--jobs", "2"]), ("cluster", ["--cluster", "local:2"])):
        out, feedback = tmp_path / f"{label}.csv", tmp_path / f"{label}-feedback"
        status = main(["grade", *folders, "--checks", str(task1_checks), "--out", str(out),
                       "--feedback", str(feedback), "--call-timeout", "10", *where])  # fmt: skip
        files = {str(path.relative_to(feedback)): comparable(path.read_text())
                 for path in sorted(feedback.rglob("*.md"))}  # fmt: skip
        runs[label] = (status, out.read_text(), files)
    assert runs["cluster"] == runs["pool"]
    status, table, files = runs["pool"]
    rows = {row["id"]: row for row in csv.DictReader(io.StringIO(table))}
    assert rows["alice"]["task1"] == rows[intake.MAX_POINTS_ID]["task1"] != "0"
    assert status == 1 and "no task files" in rows["carol"]["notes"]
    assert {"students/alice.md", "instructor/carol.md", "summary.md"} <= set(files)


def test_a_worker_killed_mid_submission_costs_a_retry(tmp_path: Path, task1_checks: Path) -> None:
    submission = grading.Submission("alice", PROJECT_ROOT / "solutions")
    with connect("local:1") as client:
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
            [submission], task1_checks, client, progress=lambda *a: progress.append(a),
            call_timeout=10.0,
        )  # fmt: skip
    assert first.graded and first.total == first.report.points > 0, first.notes
    assert [g.total for g in grades] == [first.total] and len(progress) == 1


@pytest.mark.parametrize("spec", ["local:0", "local:x", "local", ""])
def test_bad_cluster_specs_are_refused(spec: str) -> None:
    with pytest.raises(ValueError, match=r"local:N|scheduler address"):
        parse_cluster(spec)
