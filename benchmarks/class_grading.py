"""How much machine time does ``msdlab grade`` take for a class?

Workload: COUNT copies of the reference solutions (every one must get full marks) and
ENDLESS copies whose task 1 ``particle_count`` never returns, in a temporary folder
outside the clone, graded by one ``msdlab grade --jobs JOBS`` run with the course's full
checks (hidden ones included). Machine time is the processor time (user and system) of
``msdlab grade`` and of every process below it (the judges, their forkserver, the
sandboxes), read from ``/proc`` ten times a second, each process's last reading kept: it
counts only this run's work, whatever else the machine runs (a process's last tenth of a
second can be missed), in all and by part: the grader (``msdlab grade`` itself: intake,
gradebook, views), the judges (the checks, pytest, the engine's side of the calls), the
sandboxes (the submissions' code and its side of the calls). Wall time is shown too,
with the load average before and after.

    python benchmarks/class_grading.py                      # 100 students, 2 at a time
    python benchmarks/class_grading.py --count 6 --endless 1 --task-timeout 10
"""

from __future__ import annotations

import argparse
import csv
import os
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from msdlab.course import PROJECT_ROOT
from msdlab.instructor.judging import processes

ENDLESS = "\ndef particle_count(n: int = N) -> int:\n    while True:\n        pass\n"
POLL_SECONDS = 0.1


def make_class(root: Path, count: int, endless: int) -> list[str]:
    """Folders of ``count`` correct and ``endless`` looping students under ``root``."""
    folders = []
    for number in range(count + endless):
        folder = root / "class" / f"student{number:03d}"
        shutil.copytree(PROJECT_ROOT / "solutions", folder)
        if number >= count:
            task1 = folder / "task1.py"
            task1.write_text(task1.read_text(encoding="utf-8") + ENDLESS, encoding="utf-8")
        folders.append(str(folder))
    return folders


def machine_time(process: subprocess.Popen) -> dict[str, float]:
    """Processor seconds of ``process`` and everything below it, until it ends, by the part
    of grading each process does (`part_of`)."""
    seen: dict[tuple[int, str], float] = {}
    parts: dict[tuple[int, str], str] = {}
    while process.poll() is None:
        for pid in processes.descendants(process.pid):
            start = _start_time(pid)
            if start is None:
                continue
            if (pid, start) not in parts:
                parts[(pid, start)] = "grader" if pid == process.pid else part_of(pid)
            seen[(pid, start)] = max(seen.get((pid, start), 0.0), processes.cpu_of([pid]))
        time.sleep(POLL_SECONDS)
    spent = dict.fromkeys(PARTS, 0.0)
    for key, seconds in seen.items():
        spent[parts[key]] += seconds
    return spent


PARTS = ("grader", "judges", "sandboxes", "other")


def part_of(pid: int) -> str:
    """Which part of grading process ``pid`` is, from its command line: a sandbox (bubblewrap
    and the submission's process), a judge (forked from the forkserver, or started afresh
    as pytest), or other (the forkserver's resource tracker)."""
    try:
        command = Path(f"/proc/{pid}/cmdline").read_bytes().replace(b"\0", b" ").decode()
    except OSError:
        return "other"
    if "sandbox_child" in command or command.startswith("bwrap"):
        return "sandboxes"
    if "forkserver" in command or "pytest" in command:
        return "judges"
    return "other"


def _start_time(pid: int) -> str | None:
    """When ``pid`` started (clock ticks since boot), which tells a reused pid apart."""
    try:
        text = Path(f"/proc/{pid}/stat").read_text()
    except OSError:
        return None
    return text[text.rfind(")") + 2 :].split()[19]


def run(count: int, endless: int, jobs: int, task_timeout: float) -> None:
    with tempfile.TemporaryDirectory(prefix="msdlab-bench-") as folder:
        root = Path(folder)
        students = make_class(root, count, endless)
        out = root / "grades.csv"
        command = [sys.executable, "-c", "from msdlab.cli import main; raise SystemExit(main())",
                   "grade", *students, "--out", str(out), "--jobs", str(jobs),
                   "--task-timeout", str(task_timeout)]  # fmt: skip
        load = os.getloadavg()[0]
        started = time.perf_counter()
        process = subprocess.Popen(command, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
        spent = machine_time(process)
        seconds = sum(spent.values())
        wall = time.perf_counter() - started
        errors = process.stderr.read().decode(errors="replace")
        rows = list(csv.DictReader(out.open(encoding="utf-8")))
        full = rows[0]["total"]
        correct = [r for r in rows[1:] if int(r["id"].removeprefix("student")) < count]
        wrong = [r["id"] for r in correct if r["total"] != full]
        assert not wrong, f"not full marks: {wrong}\n{errors[-2000:]}"
        print(f"{count} correct + {endless} endless students, --jobs {jobs}, "
              f"--task-timeout {task_timeout:g}: exit {process.returncode}")  # fmt: skip
        print(f"machine time {seconds:7.1f} s, {seconds / (count + endless):5.2f} s a student")
        for part, used in spent.items():
            print(f"  {part:<10} {used:7.1f} s, {used / (count + endless):5.2f} s a student")
        print(f"wall time    {wall:7.1f} s, {wall / (count + endless):5.2f} s a student")
        print(f"load average {load:.1f} before, {os.getloadavg()[0]:.1f} after, "
              f"{os.cpu_count()} processors")  # fmt: skip


if __name__ == "__main__":
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--count", type=int, default=100, help="correct students (%(default)s)")
    parser.add_argument("--endless", type=int, default=0, help="looping students (%(default)s)")
    parser.add_argument("--jobs", type=int, default=2, help="submissions at once (%(default)s)")
    parser.add_argument(
        "--task-timeout", type=float, default=60.0, help="msdlab grade's (%(default)s)"
    )
    arguments = parser.parse_args()
    run(arguments.count, arguments.endless, arguments.jobs, arguments.task_timeout)
