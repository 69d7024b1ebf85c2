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
"""

from __future__ import annotations

import contextlib
import multiprocessing
import os
import signal
import sys
from pathlib import Path

PRELOAD = ["__main__", "hypothesis.strategies", "pytest", "scipy.linalg", "scipy.sparse", "msdlab"]


class ForkedJudges:
    """Runs pytest in judges forked from the forkserver (started at the first judge)."""

    def __init__(self) -> None:
        self.context = multiprocessing.get_context("forkserver")
        self.context.set_forkserver_preload(PRELOAD)

    def run(
        self, arguments: list[str], cwd: Path, environment: dict[str, str], timeout: float
    ) -> tuple[int | None, str]:
        """Run pytest with ``arguments`` in a forked judge; its exit status (None if it was
        killed after ``timeout`` seconds) and what it wrote to stderr."""
        errors = cwd / "judge-stderr.txt"
        judge = self.context.Process(
            target=_judge, args=(arguments, str(cwd), environment, str(errors)), daemon=True
        )
        judge.start()
        judge.join(timeout)
        status = judge.exitcode
        judge.kill()  # if it has not made its own session yet
        with contextlib.suppress(ProcessLookupError, PermissionError):
            os.killpg(judge.pid, signal.SIGKILL)  # over time, and anything left behind
        judge.join()
        judge.close()
        try:
            return status, errors.read_text(errors="replace")
        except OSError:
            return status, ""


def _judge(arguments: list[str], cwd: str, environment: dict[str, str], errors: str) -> None:
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
        stderr = os.open(errors, os.O_WRONLY | os.O_CREAT | os.O_TRUNC, 0o600)
        for fd, target in ((quiet, 0), (quiet, 1), (stderr, 2)):
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
