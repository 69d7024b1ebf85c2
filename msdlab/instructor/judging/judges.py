"""Judges forked from multiprocessing's forkserver, which has imported what every judge imports.

A fresh judge spends about a CPU-second importing pytest, hypothesis, scipy and msdlab.
`ForkedJudges` starts each judge as a `multiprocessing` process of the ``forkserver``
start method with those modules preloaded (`multiprocessing.set_forkserver_preload`): a
child of a server process of the grader's user, started once, that becomes the judge (its
own session, working folder, environment and stderr file) and runs pytest with the judge's
arguments. Each child starts from the server's untouched state, so nothing passes from one
submission's judge to the next; the submission itself still runs only in its sandbox, which
the judge starts. As with any ``forkserver`` child, a script that grades must keep its work
under ``if __name__ == "__main__":`` (each judge imports the script that started it).

The server listens on a socket file in multiprocessing's temporary folder, under ``TMPDIR``;
a socket's path holds at most 107 bytes, so where ``TMPDIR`` is too deep for it the folder
is made in ``/tmp`` instead (`_short_socket_folder`). Where no server can start, each judge
starts afresh (about a processor-second more a submission) and the grader says so once.

The server is started with Python's safe-path setting (``PYTHONSAFEPATH``, Python 3.11 and
later): its imports come from the installed packages, never from the folder grading runs
in, where a clone of the course (a folder named ``msdlab``) would shadow the installed
msdlab. Older Pythons have no such setting: there every judge is started afresh instead.
"""

from __future__ import annotations

import contextlib
import multiprocessing
import os
import sys
import tempfile
import threading
from multiprocessing import forkserver, util
from pathlib import Path

from . import processes

PRELOAD = ["__main__", "hypothesis.strategies", "pytest", "scipy.linalg", "scipy.sparse", "msdlab"]
SAFE_PATH = sys.version_info >= (3, 11)  # PYTHONSAFEPATH: no working folder on sys.path
SOCKET_PATH_BYTES = 107  # a socket file's path, less its closing NUL (Linux's sun_path)
SOCKET_NAME_BYTES = len("/pymp-12345678/listener-12345678")  # multiprocessing's names in it
_STARTING = threading.Lock()
TIMES = "MSDLAB_JUDGE_TIMES"
"""The environment variable naming the file a judge writes its processor time to."""


class ForkedJudges:
    """Runs pytest in judges forked from the forkserver (started at the first judge)."""

    def __init__(self) -> None:
        self.context = multiprocessing.get_context("forkserver")
        self.context.set_forkserver_preload(PRELOAD)
        self._said_why = False

    def unavailable(self, error: BaseException) -> None:
        """Say once, on stderr, that judges start afresh because of ``error``."""
        if not self._said_why:
            self._said_why = True
            print(f"msdlab grade: no judge server ({type(error).__name__}: {error}); each judge "
                  "starts afresh, about a processor-second more a submission",
                  file=sys.stderr)  # fmt: skip

    def run(
        self, arguments: list[str], cwd: Path, environment: dict[str, str], timeout: float
    ) -> processes.Judged:
        """Run pytest with ``arguments`` in a forked judge: its exit status (None if it was
        killed after ``timeout`` seconds) and what it printed (stdout and stderr). OSError where no
        server can start whose imports are safe from the working folder."""
        _start_server()
        output = cwd / "judge-output.txt"
        judge = self.context.Process(
            target=_judge, args=(arguments, str(cwd), environment, str(output)), daemon=True
        )
        judge.start()
        with processes.RUNNING.judge(judge.pid):
            judge.join(timeout)
            status = judge.exitcode
            left = processes.remains(judge.pid) if status is None else None
            processes.kill_tree(judge.pid)  # over time, and anything left behind
        judge.join()
        judge.close()
        try:
            return processes.Judged(status, output.read_text(errors="replace"), left)
        except OSError:
            return processes.Judged(status, "", left)


def server_seconds() -> float:
    """Processor seconds the judges' server of this process has used itself (0 if none runs;
    its judges are counted by each judge)."""
    pid = getattr(forkserver._forkserver, "_forkserver_pid", None)
    return processes.cpu_of([pid]) if pid else 0.0


def _start_server() -> None:
    """Start the forkserver unless it runs, with no working folder on its ``sys.path``."""
    if not SAFE_PATH:
        raise OSError("a forkserver would import from the working folder before Python 3.11")
    with _STARTING:
        _short_socket_folder()
        before = os.environ.get("PYTHONSAFEPATH")
        os.environ["PYTHONSAFEPATH"] = "1"  # inherited by the server, read at its start
        try:
            forkserver.ensure_running()
        finally:
            if before is None:
                del os.environ["PYTHONSAFEPATH"]
            else:
                os.environ["PYTHONSAFEPATH"] = before


def _short_socket_folder() -> None:
    """Make multiprocessing's temporary folder, where the server's socket file goes, in
    ``/tmp`` when one under ``TMPDIR`` would make the socket's path too long."""
    if len(tempfile.gettempdir()) + SOCKET_NAME_BYTES <= SOCKET_PATH_BYTES:
        return
    chosen = tempfile.tempdir
    tempfile.tempdir = "/tmp"
    try:
        util.get_temp_dir()  # made now and kept for the process (removed at its exit)
    finally:
        tempfile.tempdir = chosen


def _judge(arguments: list[str], cwd: str, environment: dict[str, str], output: str) -> None:
    """In the forked child: become the judge of one submission and exit with pytest's status."""
    code = 3
    try:
        os.setsid()
        os.chdir(cwd)
        os.environ.clear()
        os.environ.update(environment)
        import tempfile

        tempfile.tempdir = None  # found again from the judge's TMPDIR
        sys.dont_write_bytecode = True
        quiet = os.open(os.devnull, os.O_RDWR)
        printed = os.open(output, os.O_WRONLY | os.O_CREAT | os.O_TRUNC, 0o600)
        for fd, target in ((quiet, 0), (printed, 1), (printed, 2)):
            os.dup2(fd, target)
        import pytest

        sys.argv = ["pytest", *arguments]
        code = int(pytest.main(arguments))
    except BaseException:  # whatever happens, the child must not return
        import traceback

        traceback.print_exc()
    finally:
        with contextlib.suppress(Exception):
            sys.stdout.flush()
            sys.stderr.flush()
        os._exit(code)
