"""Judges forked from one process that has already imported pytest, hypothesis and msdlab.

A fresh judge spends about a CPU-second importing what every judge imports.
`grading.grade_all` starts a `JudgeServer` per slot instead: a process of the
grader's user that imports those once and, for each submission, forks a child
that becomes the judge (its own session, working folder, environment and
stderr file) and runs pytest with the judge's arguments. Each child starts from
the server's untouched state, so nothing passes from one submission's judge to
the next; the submission itself still runs only in its sandbox, which the judge
starts. Run as ``python -m msdlab.instructor.judge_server``: one JSON request a
line on stdin, the child's pid and then its exit status a line each on stdout.
"""

from __future__ import annotations

import contextlib
import json
import os
import select
import signal
import subprocess
import sys
import time
from pathlib import Path


class JudgeServer:
    """The grader's side: a server process, restarted if it is found dead."""

    command = (sys.executable, "-m", "msdlab.instructor.judge_server")

    def __init__(self, environment: dict[str, str]) -> None:
        self.environment = environment
        self.process: subprocess.Popen | None = None

    def run(
        self, arguments: list[str], cwd: Path, environment: dict[str, str], timeout: float
    ) -> tuple[int | None, str]:
        """Run pytest with ``arguments`` in a forked judge; its exit status (None if it was
        killed after ``timeout`` seconds) and what it wrote to stderr."""
        if self.process is None or self.process.poll() is not None:
            self._start()
        assert self.process is not None and self.process.stdin and self.process.stdout
        errors = cwd / "judge-stderr.txt"
        request = {"argv": arguments, "cwd": str(cwd), "env": environment, "stderr": str(errors)}
        deadline = time.monotonic() + timeout
        self.process.stdin.write(json.dumps(request).encode() + b"\n")
        self.process.stdin.flush()
        pid = int(self._line(deadline + 60.0))
        try:
            status: int | None = int(self._line(deadline))
        except TimeoutError:
            with contextlib.suppress(ProcessLookupError, PermissionError):
                os.killpg(pid, signal.SIGKILL)
            self._line(time.monotonic() + 60.0)  # the server has reaped it
            status = None
        finally:
            with contextlib.suppress(ProcessLookupError, PermissionError):
                os.killpg(pid, signal.SIGKILL)  # and anything left behind
        try:
            return status, errors.read_text(errors="replace")
        except OSError:
            return status, ""

    def _start(self) -> None:
        self.close()
        self.process = subprocess.Popen(
            self.command,
            stdin=subprocess.PIPE,
            stdout=subprocess.PIPE,
            stderr=subprocess.DEVNULL,
            env=self.environment,
            start_new_session=True,
        )

    def _line(self, deadline: float) -> str:
        """The server's next line; TimeoutError after ``deadline``, EOFError if it died."""
        assert self.process is not None and self.process.stdout
        out = self.process.stdout
        ready, _, _ = select.select([out], [], [], max(deadline - time.monotonic(), 0.0))
        if not ready:
            raise TimeoutError
        line = out.readline()
        if not line:
            self.close()
            raise EOFError("the judge server died")
        return line.decode()

    def close(self) -> None:
        """Stop the server process (between submissions: no judge of it is running)."""
        if self.process is not None:
            with contextlib.suppress(ProcessLookupError):
                self.process.kill()
            self.process.wait()
            for stream in (self.process.stdin, self.process.stdout):
                with contextlib.suppress(OSError):
                    stream.close()
            self.process = None


def serve() -> None:
    """Import what every judge needs, then fork a judge per request until stdin closes."""
    import hypothesis.strategies  # noqa: F401  what the checks import; most of the start-up
    import pytest  # noqa: F401
    import scipy.linalg
    import scipy.sparse  # noqa: F401

    import msdlab  # noqa: F401

    requests, replies = sys.stdin.buffer, sys.stdout.buffer
    for line in requests:
        request = json.loads(line)
        replies.flush()
        pid = os.fork()
        if pid == 0:
            _judge(request)
        replies.write(f"{pid}\n".encode())
        replies.flush()
        _, status = os.waitpid(pid, 0)
        replies.write(f"{os.waitstatus_to_exitcode(status)}\n".encode())
        replies.flush()


def _judge(request: dict) -> None:
    """In the forked child: become the judge of one submission and exit with pytest's status."""
    code = 3
    try:
        os.setsid()
        os.chdir(request["cwd"])
        os.environ.clear()
        os.environ.update(request["env"])
        import tempfile

        tempfile.tempdir = None  # found again from the judge's TMPDIR
        quiet = os.open(os.devnull, os.O_RDWR)
        errors = os.open(request["stderr"], os.O_WRONLY | os.O_CREAT | os.O_TRUNC, 0o600)
        for fd, target in ((quiet, 0), (quiet, 1), (errors, 2)):
            os.dup2(fd, target)
        import pytest

        sys.argv = ["pytest", *request["argv"]]
        code = int(pytest.main(request["argv"]))
    except BaseException:  # whatever happens, the child must not return
        import traceback

        traceback.print_exc()
    finally:
        with contextlib.suppress(Exception):
            sys.stdout.flush()
            sys.stderr.flush()
        os._exit(code)


if __name__ == "__main__":
    serve()
