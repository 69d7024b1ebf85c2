"""Running the checks in a fresh pytest process and reading back their report.

`CheckRun` is the one way the checks run: ``msdlab check`` and the notebooks'
`Course.check` (`run_checks`: the checks of one task or all, on a folder of task files)
and ``msdlab grade`` (each submission's judge, with the sandbox's plugin) start pytest with
its arguments in the `environment` made here. (``msdlab validate`` calls the same checks
in its own process, on hundreds of versions of a task file, with the fixtures the course's
plugin gives: `msdlab.course.pytest_plugin.check_arguments`.)
"""

from __future__ import annotations

import importlib.util
import os
import select
import shlex
import shutil
import subprocess
import sys
import tempfile
import time
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from pathlib import Path

from . import PROJECT_ROOT, TASKS, loader
from .report import CheckReport
from .task_budget import TASK_TIMEOUT

CHECKS = Path("tests") / "tasks"
PLUGINS = ("msdlab.course.pytest_plugin", "_hypothesis_pytestplugin", "pytest_timeout")
"""The pytest plugins the checks run with: the course's, Hypothesis' and pytest-timeout (the
course's pytest config sets its ``timeout``). Only these load: pytest's search of every
installed package for plugins (xdist, anyio, nbval, ...) cost a second."""
CALL_TIMEOUT = 10.0
"""Seconds one call into a task file may take by default (`call_limit`); the slowest call the
reference solutions make takes well under a second."""


class ChecksDidNotRun(RuntimeError):
    """pytest ended without a report (a broken checks folder, a crash, a timeout)."""

    def __init__(self, message: str, output: str = "") -> None:
        super().__init__(message)
        self.output = output


@dataclass(frozen=True)
class CheckRun:
    """One run of the checks in a pytest process of its own: the one way ``msdlab check``,
    the notebooks' `Course.check` and ``msdlab grade`` run them.

    The checks in ``checks`` (of ``task``, None: every task; the hidden ones only with
    ``hidden``) on the task files in ``implementation``; the JSON `CheckReport` goes to
    ``report``, the points of every check found to ``points`` (`manifest`). Each call into
    a task file may take ``call_timeout`` seconds (None: the course plugin's default, or
    what a plugin of ``plugins`` that runs the task files elsewhere says). ``workspace``:
    a folder to stand in that holds nothing but the run (grading's), where no pytest
    configuration around the checks applies. ``options``: further options of ``plugins``.
    """

    checks: Path
    implementation: Path
    report: Path
    task: int | None = None
    hidden: bool = False
    call_timeout: float | None = None
    points: Path | None = None
    verbose: bool = False
    plugins: tuple[str, ...] = PLUGINS
    options: tuple[str, ...] = ()
    workspace: Path | None = None
    task_timeout: float | None = None
    progress: int | None = None

    def arguments(self) -> list[str]:
        """pytest's arguments: only the files of `task` where it is given (collecting the
        others' takes a second), its checks chosen by marker (every check found with
        `hidden` and no task), the report asked for."""
        marker = f"task{self.task}" if self.task else ""
        if not self.hidden:
            marker = f"({marker or ' or '.join(f'task{n}' for n in TASKS)}) and not hidden"
        files = sorted(self.checks.glob(f"test_task{self.task}.py")) + sorted(
            self.checks.glob(f"test_task{self.task}_*.py")
        )
        arguments = [
            *(map(str, files) if self.task and files else [str(self.checks)]),
            *(option for name in self.plugins for option in ("-p", name)),
            f"--impl={self.implementation}",
            f"--msdlab-report={self.report}",
            *(["-m", marker] if marker else []),
            "-p", "no:cacheprovider",
            "--tb=short" if self.verbose else "--tb=no",
            "-q",
        ]  # fmt: skip
        if self.call_timeout is not None:
            arguments.append(f"--call-timeout={self.call_timeout:g}")
        if self.task_timeout is not None:
            arguments.append(f"--task-timeout={self.task_timeout:g}")
        if self.points is not None:
            arguments.append(f"--msdlab-points={self.points}")
        if self.progress is not None:
            arguments.append(f"--msdlab-progress={self.progress}")
        if self.workspace is not None:
            arguments += ["--no-header", "--confcutdir", str(self.checks)]
            arguments += ["--rootdir", str(self.workspace), "-o", "addopts="]
        return [*arguments, *self.options]

    def command(self) -> list[str]:
        """The command line of a fresh pytest process that runs `arguments`."""
        return [sys.executable, "-m", "pytest", *self.arguments()]


def environment(base: Mapping[str, str] | None = None) -> dict[str, str]:
    """The environment the checks' pytest process runs in: ``base`` (default: this
    process's) with

    - the numpy kernel unless ``MSDLAB_KERNEL`` says otherwise: the checks' bodies are
      small, compiling them would cost more than it saves;
    - no bytecode written (``PYTHONDONTWRITEBYTECODE``): no ``__pycache__`` beside the task
      files and the checks, which compile in milliseconds; everything else loads the
      bytecode its installer wrote (`compile_msdlab` writes msdlab's own);
    - only the plugins named (`PLUGINS`, ``PYTEST_DISABLE_PLUGIN_AUTOLOAD``).
    """
    return {
        "MSDLAB_KERNEL": "numpy",
        **(os.environ if base is None else base),
        "PYTHONDONTWRITEBYTECODE": "1",
        "PYTEST_DISABLE_PLUGIN_AUTOLOAD": "1",
    }


def compile_msdlab() -> None:
    """Write the bytecode of msdlab's modules that is missing or out of date (an editable
    install, a release folder: no installer compiled them), so that the checks' process,
    which writes none (`environment`), loads them compiled. Up to date, this only compares
    times (milliseconds); a folder the user cannot write to is left as it is."""
    if sys.dont_write_bytecode:
        return
    import compileall

    compileall.compile_dir(PROJECT_ROOT / "msdlab", quiet=2, workers=1)


Progress = Callable[[str | None], None]
"""Told ``'task 2: name'`` as each check starts, and None about once a second meanwhile."""


def run_checks(
    checks: Path,
    folder: Path,
    task: int | None = None,
    *,
    hidden: bool = False,
    verbose: bool = False,
    timeout: float = 900.0,
    save: Path | None = None,
    call_timeout: float = CALL_TIMEOUT,
    task_timeout: float = TASK_TIMEOUT,
    points: Path | None = None,
    progress: Progress | None = None,
) -> tuple[CheckReport, str]:
    """Run the checks of ``task`` (None: all tasks) on the task files in ``folder`` (a
    `CheckRun` standing in ``checks``).

    Returns the report and pytest's output; ``save`` keeps a copy of the JSON report,
    ``points`` gets the points manifest of every check found (`manifest`). Hidden checks
    run only with ``hidden``. Each call into a task file may take ``call_timeout``
    seconds, the checks of each task ``task_timeout`` seconds of processor time (as when
    graded), the whole run ``timeout``; ``progress`` hears of each check as it starts.
    """
    compile_msdlab()
    with tempfile.TemporaryDirectory(prefix="msdlab-check-") as scratch:
        report_path = Path(scratch) / "report.json"
        read_end, write_end = os.pipe()
        run = CheckRun(
            checks, folder, report_path, task, hidden, call_timeout, points, verbose,
            task_timeout=task_timeout, progress=write_end,
        )  # fmt: skip
        try:
            process = subprocess.Popen(
                run.command(),
                cwd=checks,
                env=environment(),
                stdin=subprocess.DEVNULL,
                stdout=subprocess.PIPE,
                stderr=subprocess.STDOUT,
                pass_fds=(write_end,),
            )
        finally:
            os.close(write_end)
        with os.fdopen(read_end, "rb") as lines:
            returncode, output = _watch(process, lines, timeout, progress or (lambda _: None))
        if not report_path.exists() or returncode not in (0, 1):
            raise ChecksDidNotRun(
                f"the checks could not run (pytest exit status {returncode})", output
            )
        if save is not None:
            shutil.copyfile(report_path, save)
        return CheckReport.read(report_path), output


def _watch(process: subprocess.Popen, lines, timeout: float, progress: Progress) -> tuple[int, str]:
    """Wait for the checks' ``process``, telling ``progress`` of each check it starts (read
    from ``lines``); its exit status and output. After ``timeout`` seconds, or when the wait
    is interrupted (Ctrl-C, a notebook's interrupt, which reaches this process only), it is
    ended."""
    try:
        return _read(process, lines, timeout, progress)
    except BaseException:
        process.kill()
        process.wait()
        raise


def _read(process: subprocess.Popen, lines, timeout: float, progress: Progress) -> tuple[int, str]:
    """`_watch`'s reading, until ``process`` ends or ``timeout`` seconds have passed."""
    deadline, output, last, buffer = time.monotonic() + timeout, bytearray(), "", b""
    streams = [process.stdout, lines]
    while process.stdout in streams:
        if time.monotonic() > deadline:
            raise ChecksDidNotRun(
                f"the checks did not finish within {timeout:g} s"
                + (f" (the last one started: {last})" if last else "")
            )
        for stream in select.select(streams, [], [], 1.0)[0]:
            data = os.read(stream.fileno(), 65536)
            if not data:
                streams.remove(stream)
            elif stream is process.stdout:
                output += data
            else:
                *complete, buffer = (buffer + data).split(b"\n")
                for line in complete:
                    task, _, name = line.decode(errors="replace").partition(" ")
                    last = f"task {task}: {name}"
                    progress(last)
        progress(None)
    return process.wait(), output.decode(errors="replace")


def missing_test_tools() -> list[str]:
    """The modules the checks need that are not installed (pytest and its plugins)."""
    needed = ("pytest", "hypothesis", "pytest_timeout")
    return [name for name in needed if importlib.util.find_spec(name) is None]


def install_command(cwd: Path) -> str:
    """The command that installs what the checks need (the ``grade`` extra) into this Python:
    of the course folder ``cwd`` is in when it is an installable project, else of msdlab."""
    python = shlex.quote(sys.executable)
    for root in (loader.course_root(cwd), PROJECT_ROOT):
        if (root / "pyproject.toml").is_file():
            return f"{python} -m pip install -e {shlex.quote(f'{root}[grade]')}"
    return f"{python} -m pip install 'msdlab[grade]'"


def checks_folder(given: Path | None, cwd: Path) -> Path:
    """The folder of the checks: given, else the course's tests/tasks (yours first)."""
    if given is None:
        local = loader.course_root(cwd) / CHECKS
        given = local if local.is_dir() else PROJECT_ROOT / CHECKS
    folder = Path(given).expanduser().resolve()
    if not folder.is_dir():
        raise FileNotFoundError(f"no checks folder at {folder}")
    return folder


def implementation_spec(given: str | None) -> str:
    """The task files asked for: ``given``, else ``$MSDLAB_IMPL``, else the student's."""
    return given or os.environ.get(loader.ENV_IMPL) or loader.DEFAULT


def implementation_folder(spec: str, cwd: Path) -> Path:
    """The folder of task files ``spec`` names; the course folder ``cwd`` is in comes first."""
    if spec in loader.NAMED:
        local = loader.course_root(cwd) / spec
        folder = local if local.is_dir() else PROJECT_ROOT / spec
    else:
        folder = Path(spec).expanduser()
    folder = folder.resolve()
    if not folder.is_dir():
        raise FileNotFoundError(f"no folder of task files at {folder}")
    return folder
