"""Judges forked from the forkserver (`ForkedJudges`): each starts from the server's state,
gets its own environment, and one that runs too long is killed without taking the server
with it."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import textwrap
import time
from multiprocessing import forkserver
from pathlib import Path

import pytest

from msdlab.course import runner
from msdlab.instructor.judging import grading
from msdlab.instructor.judging.judges import SOCKET_PATH_BYTES, ForkedJudges

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
        judged = judge(server, tmp_path / name)
        assert judged.status == 0, judged.printed


def test_a_judge_over_its_time_limit_is_killed_and_the_next_one_runs(server, tmp_path):
    (tmp_path / "slow").mkdir()
    slow = judge(server, tmp_path / "slow", timeout=3.0, SLEEP="1")
    assert slow.status is None and slow.remains is not None
    assert slow.remains.judge > 0 and 0 <= slow.remains.waited < 60  # read before its end
    (tmp_path / "next").mkdir()
    assert judge(server, tmp_path / "next").status == 0


def test_a_dead_server_is_started_again(server, tmp_path):
    (tmp_path / "first").mkdir()
    assert judge(server, tmp_path / "first").status == 0
    pid = forkserver._forkserver._forkserver_pid
    os.kill(pid, signal.SIGKILL)
    deadline = time.monotonic() + 30
    while Path(f"/proc/{pid}/stat").read_text().split()[2] != "Z":  # dead, not yet reaped
        assert time.monotonic() < deadline
        time.sleep(0.05)
    (tmp_path / "second").mkdir()
    assert judge(server, tmp_path / "second").status == 0


FORKED_UNDER_A_DEEP_TMPDIR = """
import os, sys, tempfile
from multiprocessing import forkserver
from pathlib import Path
from msdlab.course import runner
from msdlab.instructor.judging.judges import ForkedJudges

if __name__ == "__main__":
    folder = Path(sys.argv[1])
    assert len(tempfile.gettempdir()) > 80, tempfile.gettempdir()
    arguments = ["-q", "-p", "no:cacheprovider", "--rootdir", str(folder), str(folder)]
    judged = ForkedJudges().run(arguments, folder, runner.environment(), 120.0)
    assert judged.status == 0, judged.printed
    print(forkserver._forkserver._forkserver_pid)
"""


def test_a_temporary_folder_too_deep_for_a_socket_still_gets_a_judge_server(tmp_path):
    deep = tmp_path / ("d" * (SOCKET_PATH_BYTES - len(str(tmp_path))))
    deep.mkdir()
    (tmp_path / "checks").mkdir()
    (tmp_path / "checks" / "test_one.py").write_text("def test_one():\n    pass\n")
    (tmp_path / "grade.py").write_text(FORKED_UNDER_A_DEEP_TMPDIR)
    done = subprocess.run([sys.executable, str(tmp_path / "grade.py"), str(tmp_path / "checks")],
                          env={**os.environ, "TMPDIR": str(deep)}, cwd=tmp_path,
                          capture_output=True, text=True, timeout=300)  # fmt: skip
    assert done.returncode == 0, done.stderr
    assert done.stdout.strip().isdigit()  # the server ran the judge: no fresh start


class NoServer(ForkedJudges):
    def run(self, *args: object) -> tuple[int | None, str]:
        raise OSError("AF_UNIX path too long")


def test_without_a_server_each_judge_starts_afresh_and_the_grader_says_so_once(tmp_path, capsys):
    (tmp_path / "test_one.py").write_text("def test_one():\n    pass\n")
    arguments = ["-q", "-p", "no:cacheprovider", "--rootdir", str(tmp_path), str(tmp_path)]
    server = NoServer()
    for _ in range(2):
        status = grading._judge(arguments, tmp_path, runner.environment(), 120.0, server).status
        assert status == 0
    said = capsys.readouterr().err.splitlines()
    assert said == [
        "msdlab grade: no judge server (OSError: AF_UNIX path too long); each judge starts "
        "afresh, about a processor-second more a submission"
    ]
