"""Judges forked from the forkserver (`ForkedJudges`): each starts from the server's state,
gets its own environment, and one that runs too long is killed without taking the server
with it."""

from __future__ import annotations

import os
import signal
import textwrap
import time
from multiprocessing import forkserver
from pathlib import Path

import pytest

from msdlab.course import runner
from msdlab.instructor.judging.judges import ForkedJudges

CHECKS = """
import os
import sys
import tempfile
import time


def test_starts_afresh():
    assert os.environ.get("LEFT_BY_A_JUDGE") is None and "left_by_a_judge" not in sys.modules
    os.environ["LEFT_BY_A_JUDGE"] = "1"
    sys.modules["left_by_a_judge"] = sys


def test_uses_its_own_environment():
    assert os.environ["GIVEN"] == os.getcwd()
    assert tempfile.gettempdir() == os.environ["TMPDIR"]


def test_sleeps():
    if os.environ.get("SLEEP"):
        time.sleep(60)
"""


@pytest.fixture
def server() -> ForkedJudges:
    return ForkedJudges()


def judge(server: ForkedJudges, folder: Path, timeout: float = 120.0, **settings: str):
    (folder / "tmp").mkdir(exist_ok=True)
    (folder / "test_checks.py").write_text(textwrap.dedent(CHECKS))
    environment = {**runner.environment(), "GIVEN": str(folder), "TMPDIR": str(folder / "tmp")}
    arguments = ["-q", "-p", "no:cacheprovider", "--rootdir", str(folder), str(folder)]
    return server.run(arguments, folder, {**environment, **settings}, timeout)


def test_every_judge_starts_from_the_servers_state(server, tmp_path):
    for name in ("first", "second"):
        (tmp_path / name).mkdir()
        status, errors = judge(server, tmp_path / name)
        assert status == 0, errors


def test_a_judge_over_its_time_limit_is_killed_and_the_next_one_runs(server, tmp_path):
    (tmp_path / "slow").mkdir()
    assert judge(server, tmp_path / "slow", timeout=3.0, SLEEP="1")[0] is None
    (tmp_path / "next").mkdir()
    assert judge(server, tmp_path / "next")[0] == 0


def test_a_dead_server_is_started_again(server, tmp_path):
    (tmp_path / "first").mkdir()
    assert judge(server, tmp_path / "first")[0] == 0
    pid = forkserver._forkserver._forkserver_pid
    os.kill(pid, signal.SIGKILL)
    deadline = time.monotonic() + 30
    while Path(f"/proc/{pid}/stat").read_text().split()[2] != "Z":  # dead, not yet reaped
        assert time.monotonic() < deadline
        time.sleep(0.05)
    (tmp_path / "second").mkdir()
    assert judge(server, tmp_path / "second")[0] == 0
