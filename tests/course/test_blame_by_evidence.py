"""A grade is a function of the code alone: what a submission's process does to itself is
the student's outcome, never "grader failed"; a call's time limit counts its own time, not
the time the machine kept it from a processor; the sandbox starts no other process; and the
same class gets the same rows on a quiet machine and beside a processor hog."""

from __future__ import annotations

import csv
import os
import shutil
import subprocess
import sys
import textwrap
import time
from pathlib import Path

import pytest

from msdlab.cli import main
from msdlab.course import PROJECT_ROOT
from msdlab.instructor.judging import grading, processes, sandbox

SOLUTIONS = PROJECT_ROOT / "solutions"
TASK = """
import os
import signal
import sys
import time


def ends_itself(number):
    signal.raise_signal(number)


def exits(status):
    os._exit(status)


def starts_a_process():
    import _posixsubprocess

    read, write = os.pipe()
    program = [sys.executable.encode()]
    return _posixsubprocess.fork_exec(
        program, program, True, (), None, None, -1, -1, -1, -1, -1, -1, read, write,
        True, False, False, None, None, None, -1, None, False,
    )


def starts_a_thread():
    import threading

    thread = threading.Thread(target=time.sleep, args=(0,))
    thread.start()
    thread.join()
    return 1


def sleeps(seconds):
    time.sleep(seconds)
    return seconds


def computes(seconds):
    end = time.process_time() + seconds
    while time.process_time() < end:
        pass
    return seconds
"""
NAMESPACE = sandbox.isolation_problem() is None
ISOLATIONS = [
    pytest.param("namespace", marks=pytest.mark.skipif(not NAMESPACE, reason="no bubblewrap")),
    "process",
]


@pytest.fixture(scope="module", params=ISOLATIONS)
def remote(request, tmp_path_factory):
    folder = tmp_path_factory.mktemp("submission")
    (folder / "task1.py").write_text(TASK)
    folder.chmod(0o755)  # as root the sandbox runs as another user
    (folder / "task1.py").chmod(0o644)
    implementation = sandbox.RemoteImplementation(
        folder, isolation=request.param, timeout=0.5, task_timeout=30.0
    )
    yield implementation
    implementation.close()


def call(remote: sandbox.RemoteImplementation, name: str, *args: object) -> object:
    remote.begin_check(1)
    return getattr(remote.task(1), name)(*args)


@pytest.mark.parametrize("signal_name", ["SIGKILL", "SIGTERM"])
def test_a_process_that_ends_itself_by_a_signal_is_the_students_crash(remote, signal_name):
    import signal

    with pytest.raises(sandbox.SubmissionCrashed, match=f"ended by the signal {signal_name}"):
        call(remote, "ends_itself", int(signal.Signals[signal_name]))


def test_an_exit_status_of_a_killed_bubblewrap_child_is_the_students(remote):
    with pytest.raises(sandbox.SubmissionCrashed):
        call(remote, "exits", 128 + 9)


def test_the_sandbox_can_start_no_process_and_no_thread(remote):
    """In both isolations, as root too (whom Linux never holds to the process limit)."""
    with pytest.raises(BlockingIOError):
        call(remote, "starts_a_process")
    with pytest.raises(RuntimeError, match="can't start new thread"):
        call(remote, "starts_a_thread")


def test_a_sleeper_is_told_it_waited_not_that_it_looped(remote):
    with pytest.raises(sandbox.SubmissionWaited, match="waiting \\(sleeping or blocked\\)"):
        call(remote, "sleeps", 100.0)


def test_a_call_kept_from_the_processor_is_not_out_of_its_own_time(remote, monkeypatch):
    """Where the scheduling figures say the sandbox waited for a processor all the time it
    did not compute (as beside a hog), 1.2 s of wall-clock time are not 0.5 s of its own."""
    waits = lambda self: time.monotonic() - self._processor_time()  # noqa: E731
    monkeypatch.setattr(sandbox.SandboxProcess, "_waits", waits)
    assert call(remote, "sleeps", 1.2) == 1.2


def test_a_call_starved_many_times_its_limit_is_the_machines_failure(remote, monkeypatch):
    monkeypatch.setattr(sandbox.SandboxProcess, "_waits", lambda self: time.monotonic())
    monkeypatch.setattr(sandbox, "STARVED_FACTOR", 3.0)
    started = time.monotonic()
    with pytest.raises(sandbox.MachineBusy, match="waited for a processor"):
        call(remote, "sleeps", 100.0)
    assert time.monotonic() - started < 30


def test_only_a_killed_bubblewrap_is_blamed_on_the_machine():
    """The judge's outcome: a check that ended with the sandbox lost is the grader's failure,
    a judge ended after its time is the student's unless its processes waited for a
    processor most of it."""
    starved = processes.Judged(None, "", processes.Remains(waited=7.0, judge=1.0, sandboxes=1.0))
    quiet = processes.Judged(None, "", processes.Remains(waited=0.1, judge=1.0, sandboxes=7.0))
    assert grading._outcome_notes(None, starved, 10.0)[0].startswith(grading.GRADER_ERROR)
    assert grading._outcome_notes(None, quiet, 10.0) == ["grading timed out after 10 s"]


CLASS = {
    "correct": "",
    "loops": "def particle_count(n: int = N) -> int:\n    while True:\n        pass\n",
    "sleeps": "def particle_count(n: int = N) -> int:\n    time.sleep(1000)\n",
    "forks": textwrap.dedent("""
        def particle_count(n: int = N) -> int:
            import _posixsubprocess
            import sys
            program = [sys.executable.encode(), b"-c", b"while True: pass"]
            read, write = os.pipe()
            for _ in range(4):
                _posixsubprocess.fork_exec(program, program[:1], True, (), None, None, -1, -1,
                    -1, -1, -1, -1, read, write, True, False, False, None, None, None, -1,
                    None, False)
            return n**3
    """),
    "kills": "def particle_count(n: int = N) -> int:\n    signal.raise_signal(signal.SIGKILL)\n",
}


def graded_class(root: Path, checks: Path, run: str) -> dict[str, tuple[str, ...]]:
    """Each student's points and notes, graded with small budgets and no retries."""
    folders = []
    for name, extra in CLASS.items():
        folder = root / run / name
        shutil.copytree(SOLUTIONS, folder)
        text = (folder / "task1.py").read_text()
        (folder / "task1.py").write_text(f"{text}\nimport os, signal, time\n{extra}")
        folders.append(str(folder))
    out, feedback = root / run / "grades.csv", root / run / "feedback"
    status = main(["grade", *folders, "--out", str(out), "--checks", str(checks), "--jobs", "2",
                   "--task-timeout", "1", "--call-timeout", "2", "--retries", "0",
                   "--feedback", str(feedback)])  # fmt: skip
    assert status == 0  # every one graded; never the grader's failure (2)
    told = (feedback / "students" / "kills.md").read_text()
    assert "ended by the signal SIGKILL" in told and "grader" not in told
    rows = csv.DictReader(out.open(encoding="utf-8"))
    return {row["id"]: (row["task1"], row["total"], row["notes"]) for row in rows}


@pytest.mark.skipif(not NAMESPACE, reason="the namespace sandbox is not available")
def test_the_same_class_gets_the_same_rows_beside_a_processor_hog(tmp_path):
    checks = tmp_path / "checks"
    checks.mkdir()
    for name in ("conftest.py", "test_task1.py"):
        shutil.copy(PROJECT_ROOT / "tests" / "tasks" / name, checks)
    quiet = graded_class(tmp_path, checks, "quiet")
    hog = "while True: pass"
    hogs = [subprocess.Popen([sys.executable, "-c", hog]) for _ in range(2 * os.cpu_count())]
    try:
        busy = graded_class(tmp_path, checks, "busy")
    finally:
        for process in hogs:
            process.kill()
            process.wait()
    assert busy == quiet
    assert quiet["correct"][1] == quiet["(max points)"][1]
    for name in ("loops", "sleeps", "forks", "kills"):
        assert quiet[name][1] < quiet["correct"][1] and "grader" not in quiet[name][2]
    assert "endless loop" in quiet["loops"][2] and "sleeping or blocked" in quiet["sleeps"][2]
    assert "died" in quiet["kills"][2]
    assert int(quiet["loops"][0]) > 0  # the loop costs particle_count's checks, not the task
