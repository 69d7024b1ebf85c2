"""The processor time a submission's calls are charged (`ProcessorClock`) and the task budget
it feeds: an endless loop costs its task's budget once, a later task has its own, and the
clock follows the sandbox when it is started again."""

from __future__ import annotations

import os
import subprocess
import sys
import time

import pytest

from msdlab.instructor.judging import processes, sandbox

SPIN = """
import time

end = time.process_time() + {seconds}
while time.process_time() < end:
    pass
"""

TASK = """
def spin():
    while True:
        pass


def quick():
    return 1
"""


def test_the_clock_reads_what_the_processes_used_and_forgets_one_that_ended():
    child = subprocess.Popen([sys.executable, "-c", SPIN.format(seconds=2.0)])
    clock = processes.ProcessorClock([child.pid])
    try:
        deadline = time.monotonic() + 100
        while clock.seconds() < 0.5 and time.monotonic() < deadline:
            time.sleep(0.05)
        assert clock.seconds() == pytest.approx(processes.cpu_of([child.pid]), abs=0.05)
        assert clock.seconds() >= 0.5
        os.waitid(os.P_PID, child.pid, os.WEXITED | os.WNOWAIT)  # ended, not yet reaped
        assert clock.seconds() >= 1.9
    finally:
        child.wait(timeout=60)
    assert clock.seconds() == 0.0  # reaped: its file says "no such process", no error
    clock.close()
    assert clock.seconds() == 0.0


def test_a_process_gone_before_the_clock_starts_is_not_read():
    child = subprocess.Popen([sys.executable, "-c", "pass"])
    child.wait(timeout=60)
    clock = processes.ProcessorClock([child.pid])
    assert clock.pids == [child.pid] and clock.seconds() == 0.0
    clock.close()


def test_an_endless_loop_costs_its_function_budget_once_and_the_rest_keep_theirs(tmp_path):
    """A loop in one function costs that function's checks: the task's other functions, and
    every function of a later task, are run with their own time."""
    (tmp_path / "task1.py").write_text(TASK)
    (tmp_path / "task2.py").write_text(TASK)
    remote = sandbox.RemoteImplementation(
        tmp_path, isolation="process", timeout=300.0, task_timeout=1.0
    )
    try:
        for task in (1, 2):  # the sandbox is started again after the first loop is killed
            remote.begin_check(task)
            started = time.monotonic()
            with pytest.raises(sandbox.SubmissionTimeout, match="used up the 1 s"):
                remote.task(task).spin()
            assert time.monotonic() - started < 120  # not the call's 300 s
            assert remote.sandbox.spent[task, f"task{task}.spin"] >= 1.0
            remote.begin_check(task)
            with pytest.raises(sandbox.SubmissionTimeout, match=f"not run.*task{task}.spin"):
                remote.task(task).spin()
            assert remote.task(task).quick() == 1
    finally:
        remote.close()
