"""Grading runs as an instructor meets them: two at once, interrupted and resumed, a
student who handed in nothing, a sandbox killed from outside. Task 1's checks only, to
keep them short; the reference answers must get every point."""

from __future__ import annotations

import csv
import os
import shutil
import signal
import sqlite3
import subprocess
import sys
import textwrap
import threading
import time
from pathlib import Path

import pytest

from msdlab.cli import main
from msdlab.course import PROJECT_ROOT
from msdlab.instructor.judging import processes, sandbox
from msdlab.instructor.points import gradebook_db

SOLUTIONS = PROJECT_ROOT / "solutions"
TEMPLATE = PROJECT_ROOT / "assignments"
MSDLAB = Path(sys.executable).with_name("msdlab")
# Started from a terminal, a command takes Ctrl-C; started in the background of a script
# (as a test runner may be), it inherits SIGINT ignored. The run is started as from a terminal.
AS_IN_A_TERMINAL = [
    sys.executable, "-c",
    "import os, signal, sys; signal.signal(signal.SIGINT, signal.SIG_DFL); "
    "os.execv(sys.argv[1], sys.argv[1:])",
]  # fmt: skip
ENDLESS = """
def particle_count(n: int = N) -> int:
    while True:
        pass
"""

pytestmark = pytest.mark.skipif(
    sandbox.isolation_problem() is not None, reason="the namespace sandbox is not available"
)


@pytest.fixture(scope="module")
def checks(tmp_path_factory) -> Path:
    """Task 1's checks, public and hidden."""
    folder = tmp_path_factory.mktemp("checks")
    for name in ("conftest.py", "reference_hidden.py", "test_task1.py", "test_task1_hidden.py"):
        shutil.copy(PROJECT_ROOT / "tests" / "tasks" / name, folder)
    return folder


def student(root: Path, name: str, source: Path = SOLUTIONS, extra: str = "") -> Path:
    folder = root / name
    shutil.copytree(source, folder)
    (folder / "task1.py").write_text((folder / "task1.py").read_text() + textwrap.dedent(extra))
    return folder


def rows_of(path: Path) -> dict[str, dict[str, str]]:
    return {row["id"]: row for row in csv.DictReader(path.open(encoding="utf-8"))}


def grade_command(out: Path, checks: Path, *arguments: str) -> list[str]:
    return [str(MSDLAB), "grade", *arguments, "--out", str(out), "--checks", str(checks),
            "--jobs", "2"]  # fmt: skip


def test_a_student_who_handed_in_nothing_gets_a_row_and_the_class_is_graded(tmp_path, checks):
    student(tmp_path, "heidi")
    roster = tmp_path / "roster.csv"
    roster.write_text("id,folder\nheidi,heidi\nabe,abe\ncleo,\n")
    out, notes = tmp_path / "out" / "grades.csv", tmp_path / "out" / "feedback"
    status = main(["grade", "--roster", str(roster), "--out", str(out), "--checks", str(checks),
                   "--feedback", str(notes)])  # fmt: skip
    assert status == 0
    rows = rows_of(out)
    assert rows["heidi"]["total"] == rows["(max points)"]["total"] == "15"
    for absent in ("abe", "cleo"):
        assert rows[absent]["total"] == "0" and "nothing handed in" in rows[absent]["notes"]
        assert "nothing handed in" in (notes / "students" / f"{absent}.md").read_text()
    assert "Nothing handed in (2): abe, cleo" in (notes / "summary.md").read_text()


@pytest.mark.parametrize("same_out", [True, False], ids=["same --out", "different --out"])
def test_two_runs_side_by_side_lose_nothing_and_blame_no_one(tmp_path, checks, same_out):
    runs = []
    for run, names in enumerate((("heidi", "ann"), ("bob", "cleo"))):
        folders = [str(student(tmp_path / f"class{run}", name)) for name in names]
        temporary = tmp_path / f"tmp{run}"
        temporary.mkdir()
        out = tmp_path / ("out" if same_out else f"out{run}") / "grades.csv"
        command = grade_command(out, checks, *folders)
        environment = dict(os.environ, TMPDIR=str(temporary))
        pipes = {"stdout": subprocess.PIPE, "stderr": subprocess.PIPE, "text": True}
        runs.append((out, names, subprocess.Popen(command, env=environment, **pipes)))
    for out, names, process in runs:
        _, errors = process.communicate(timeout=600)
        assert process.returncode == 0, errors
        rows = rows_of(out)
        for name in names:
            assert rows[name]["total"] == "15" and rows[name]["notes"] == "", errors
    if same_out:
        assert set(rows) == {"(max points)", "heidi", "ann", "bob", "cleo"}
        assert {record.status for record in gradebook_db.read_class(out)} == {"graded"}


def graded_count(out: Path) -> int:
    try:
        return sum(r.status == "graded" for r in gradebook_db.read_class(out))
    except ValueError:
        return 0


def test_ctrl_c_ends_the_run_at_once_and_resume_grades_exactly_the_rest(tmp_path, checks):
    names = ["loop", "heidi", "ann", "tom"]
    student(tmp_path / "class", "loop", extra=ENDLESS)
    student(tmp_path / "class", "heidi")
    student(tmp_path / "class", "ann")
    student(tmp_path / "class", "tom", source=TEMPLATE)
    folders = [str(tmp_path / "class" / name) for name in names]
    out, notes = tmp_path / "out" / "grades.csv", tmp_path / "out" / "feedback"
    (tmp_path / "tmp").mkdir()
    environment = dict(os.environ, TMPDIR=str(tmp_path / "tmp"))
    command = grade_command(out, checks, *folders, "--feedback", str(notes))
    process = subprocess.Popen([*AS_IN_A_TERMINAL, *command, "--task-timeout", "600"],
                               env=environment, text=True, stdout=subprocess.PIPE,
                               stderr=subprocess.PIPE, start_new_session=True)  # fmt: skip
    try:
        deadline = time.monotonic() + 500
        while graded_count(out) == 0 and process.poll() is None and time.monotonic() < deadline:
            time.sleep(0.5)
        os.killpg(process.pid, signal.SIGINT)  # as Ctrl-C in a terminal does
        _, errors = process.communicate(timeout=120)  # far less than the endless loop's 600 s
    finally:  # a run that outlives the test would be found by the next one
        if process.poll() is None:
            processes.kill_tree(process.pid)
    assert process.returncode == 130
    said = [line for line in errors.splitlines() if "interrupted" in line]
    assert len(said) == 1 and "Traceback" not in errors and "--resume" in said[0]
    kept = graded_count(out)
    assert kept >= 1 and f"interrupted: {kept} of 4 submissions" in said[0]
    assert not any(str(tmp_path) in _command_line(p) for p in processes.descendants(1)[1:])

    resumed = subprocess.run([*command, "--resume", "--task-timeout", "5"], env=environment,
                             text=True, capture_output=True, timeout=600)  # fmt: skip
    assert f"grading {4 - kept} submissions ({kept} unchanged since graded, skipped)" in (
        resumed.stderr
    )
    rows = rows_of(out)
    assert {name: rows[name]["total"] for name in ("heidi", "ann", "tom")} == {
        "heidi": "15", "ann": "15", "tom": "0",
    }  # fmt: skip
    assert "a call timed out" in rows["loop"]["notes"]
    assert sorted(p.stem for p in (notes / "students").iterdir()) == sorted(names)
    assert "used up the 5 s of processor time" in (notes / "instructor" / "loop.md").read_text()
    assert "4 of 4 submissions graded" in (notes / "summary.md").read_text()


def _command_line(pid: int) -> str:
    try:
        return Path(f"/proc/{pid}/cmdline").read_bytes().decode(errors="replace")
    except OSError:
        return ""


def _parent(pid: int) -> int:
    try:
        return int(Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()[1])
    except (OSError, ValueError, IndexError):
        return 0


def test_a_sandbox_killed_from_outside_is_graded_again_and_not_blamed(tmp_path, checks):
    """bubblewrap itself, outside the submission's namespaces, killed: evidence the
    submission cannot produce (it can end its own process, which is its crash)."""
    heidi = student(tmp_path / "class", "heidi")
    out, notes = tmp_path / "grades.csv", tmp_path / "feedback"
    killed = threading.Event()

    def kill_the_first_sandbox() -> None:
        while not killed.is_set():
            for pid in processes.descendants(os.getpid()):
                line = _command_line(pid)
                outer = not _command_line(_parent(pid)).startswith("bwrap")
                if "sandbox_child.py" in line and line.startswith("bwrap") and outer:
                    os.kill(pid, signal.SIGKILL)  # as another run or the OOM killer would
                    killed.set()
            time.sleep(0.05)

    killer = threading.Thread(target=kill_the_first_sandbox, daemon=True)
    killer.start()
    status = main(["grade", str(heidi), "--out", str(out), "--checks", str(checks),
                   "--feedback", str(notes), "--jobs", "1"])  # fmt: skip
    killed.set()
    assert status == 0
    assert rows_of(out)["heidi"]["total"] == "15" and rows_of(out)["heidi"]["notes"] == ""
    (record,) = gradebook_db.read_class(out)
    assert record.attempts == 2 and record.status == "graded"
    text = (notes / "students" / "heidi.md").read_text()
    assert "15 of 15 points" in text and "killed" not in text and "crash" not in text


def test_sigterm_ends_the_run_as_ctrl_c_does(tmp_path, checks):
    """Every judge and sandbox ended, no temporary folder left, the run closed in the
    gradebook, exit status 143."""
    student(tmp_path / "class", "loop", extra=ENDLESS)
    student(tmp_path / "class", "heidi")
    out = tmp_path / "out" / "grades.csv"
    (tmp_path / "tmp").mkdir()
    environment = dict(os.environ, TMPDIR=str(tmp_path / "tmp"))
    folders = [str(tmp_path / "class" / name) for name in ("loop", "heidi")]
    command = [*grade_command(out, checks, *folders), "--task-timeout", "600"]
    process = subprocess.Popen(command, env=environment, text=True, stdout=subprocess.PIPE,
                               stderr=subprocess.PIPE, start_new_session=True)  # fmt: skip
    try:
        deadline = time.monotonic() + 300
        while graded_count(out) == 0 and process.poll() is None and time.monotonic() < deadline:
            time.sleep(0.5)
        os.kill(process.pid, signal.SIGTERM)  # to the run alone, as a scheduler sends it
        _, errors = process.communicate(timeout=120)
    finally:
        if process.poll() is None:
            processes.kill_tree(process.pid)
    assert process.returncode == 143, errors
    assert "interrupted: 1 of 2 submissions" in errors and "Traceback" not in errors
    assert not any(str(tmp_path) in _command_line(p) for p in processes.descendants(1)[1:])
    assert [path for path in (tmp_path / "tmp").iterdir() if path.is_dir()] == []
    with sqlite3.connect(gradebook_db.beside(out)) as connection:
        assert connection.execute("SELECT outcome FROM runs").fetchall() == [("interrupted",)]
