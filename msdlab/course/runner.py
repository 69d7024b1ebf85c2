"""Running the checks in a fresh pytest process and reading back their report.

Used by ``msdlab check`` and by the notebooks' `Course.check`: the checks of one
task (or all) in a checks folder, on a folder of task files.
"""

from __future__ import annotations

import importlib.util
import os
import shlex
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

from . import PROJECT_ROOT, TASKS, loader
from .report import CheckReport

CHECKS = Path("tests") / "tasks"
PLUGINS = ("msdlab.course.pytest_plugin", "_hypothesis_pytestplugin", "pytest_timeout")
"""The pytest plugins the checks run with: the course's, Hypothesis' and pytest-timeout (the
course's pytest config sets its ``timeout``)."""
CALL_TIMEOUT = 10.0
"""Seconds one call into a task file may take by default (`call_limit`); the slowest call the
reference solutions make takes well under a second."""


class ChecksDidNotRun(RuntimeError):
    """pytest ended without a report (a broken checks folder, a crash, a timeout)."""

    def __init__(self, message: str, output: str = "") -> None:
        super().__init__(message)
        self.output = output


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
    points: Path | None = None,
) -> tuple[CheckReport, str]:
    """Run the checks of ``task`` (None: all tasks) on the task files in ``folder``.

    Returns the report and pytest's output; ``save`` keeps a copy of the JSON
    report, ``points`` gets the points manifest of every check found (`manifest`).
    Hidden checks run only with ``hidden``. Each call into a task file may take
    ``call_timeout`` seconds, the whole run ``timeout``. The checks run on the
    numpy kernel, as when graded (their bodies are small: no compiling), unless
    ``MSDLAB_KERNEL`` says otherwise.
    """
    with tempfile.TemporaryDirectory(prefix="msdlab-check-") as scratch:
        report_path = Path(scratch) / "report.json"
        command = pytest_command(checks, folder, task, hidden, report_path, verbose)
        command.append(f"--call-timeout={call_timeout:g}")
        if points is not None:
            command.append(f"--msdlab-points={points}")
        try:
            process = subprocess.run(
                command,
                cwd=checks,
                env={
                    "MSDLAB_KERNEL": "numpy",
                    # compiled modules kept, but outside the task and check folders
                    "PYTHONPYCACHEPREFIX": str(bytecode_cache()),
                    **os.environ,
                    # only the plugins the checks use (`PLUGINS`): the others installed
                    # beside them (xdist, anyio, nbval, ...) cost a second to load
                    "PYTEST_DISABLE_PLUGIN_AUTOLOAD": "1",
                },
                capture_output=True,
                text=True,
                timeout=timeout,
            )
        except subprocess.TimeoutExpired:
            raise ChecksDidNotRun(
                f"the checks did not finish within {timeout:g} s: is there an endless loop at "
                "the top level of a task file, or one the per-call limit cannot interrupt?"
            ) from None
        output = process.stdout + process.stderr
        if not report_path.exists() or process.returncode not in (0, 1):
            raise ChecksDidNotRun(
                f"the checks could not run (pytest exit status {process.returncode})", output
            )
        if save is not None:
            shutil.copyfile(report_path, save)
        return CheckReport.read(report_path), output


def bytecode_cache() -> Path:
    """Where the checks' process keeps the modules it compiled (``PYTHONPYCACHEPREFIX``), so
    the next run loads them (about a second less): the user's cache folder, not
    ``__pycache__`` folders beside the task files and checks."""
    cache = os.environ.get("XDG_CACHE_HOME") or Path.home() / ".cache"
    return Path(cache) / "msdlab" / "bytecode"


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


def pytest_command(
    checks: Path, folder: Path, task: int | None, hidden: bool, report: Path, verbose: bool
) -> list[str]:
    """The pytest command line that runs the chosen checks on ``folder``: only the files of
    ``task`` where it is given (collecting the others' takes a second)."""
    selected = f"task{task}" if task else " or ".join(f"task{n}" for n in TASKS)
    marker = selected if hidden else f"({selected}) and not hidden"
    files = sorted(checks.glob(f"test_task{task}.py")) + sorted(
        checks.glob(f"test_task{task}_*.py")
    )
    plugins = [option for name in PLUGINS for option in ("-p", name)]
    return [
        sys.executable,
        "-m",
        "pytest",
        *(map(str, files) if task and files else [str(checks)]),
        *plugins,
        f"--impl={folder}",
        f"--msdlab-report={report}",
        "-m",
        marker,
        "-p",
        "no:cacheprovider",
        "--tb=short" if verbose else "--tb=no",
        "-q",
    ]
