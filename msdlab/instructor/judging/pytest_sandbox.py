"""pytest plugin that runs the implementation under test in the grading sandbox.

Loaded by `msdlab.instructor.judging.grading` with ``-p msdlab.instructor.judging.pytest_sandbox``
(the student bundle has no such plugin). ``--sandbox`` makes the course plugin's
``implementation`` fixture a `RemoteImplementation`: the checks see only the data the
sandboxed submission returns.
"""

from __future__ import annotations

import json
import os
import resource
from pathlib import Path

import pytest

from ...course import TASKS, loader
from .judges import TIMES
from .sandbox import RemoteImplementation

_REMOTE = pytest.StashKey[RemoteImplementation]()
_TASK = pytest.StashKey[int | None]()  # the task of the check setting up or running


def pytest_addoption(parser: pytest.Parser) -> None:
    group = parser.getgroup("msdlab", "msdlab course checks")
    group.addoption(
        "--sandbox",
        action="store_true",
        help="run the implementation in a restricted child process and judge only the data it "
        "returns (what `msdlab grade` does)",
    )
    group.addoption(
        "--sandbox-timeout",
        type=float,
        default=60.0,
        metavar="S",
        help="with --sandbox: seconds one call into the implementation may take (default 60)",
    )
    group.addoption(
        "--sandbox-task-timeout",
        type=float,
        default=None,
        metavar="S",
        help="with --sandbox: processor seconds each function of the implementation may take "
        "in one task's checks, all its calls together; once used up, its further calls there "
        "fail at once (default: none)",
    )
    group.addoption(
        "--sandbox-memory",
        type=int,
        default=2048,
        metavar="MB",
        help="with --sandbox: memory limit of the implementation's process (default 2048 MB)",
    )


@pytest.hookimpl
def pytest_msdlab_implementation(
    config: pytest.Config, spec: str, root: Path
) -> RemoteImplementation | None:
    """With ``--sandbox``, the submission at ``spec`` in a sandbox process."""
    if not config.getoption("sandbox"):
        return None
    uid = os.environ.get("MSDLAB_SANDBOX_UID")
    remote = RemoteImplementation(
        loader.resolve(spec, root),
        label=str(spec),
        timeout=config.getoption("sandbox_timeout"),
        task_timeout=config.getoption("sandbox_task_timeout"),
        memory_bytes=config.getoption("sandbox_memory") * 2**20,
        uid=None if uid is None else int(uid),
        isolation=os.environ.get("MSDLAB_SANDBOX_ISOLATION", "namespace"),
    )
    config.stash[_REMOTE] = remote
    remote.begin_check(config.stash.get(_TASK, None))  # made while the first check sets up
    return remote


def pytest_runtest_setup(item: pytest.Item) -> None:
    """Each check starts afresh (a function that timed out in an earlier check runs again)
    and draws on its task's time."""
    task = next((n for n in TASKS if item.get_closest_marker(f"task{n}")), None)
    item.config.stash[_TASK] = task
    remote = item.config.stash.get(_REMOTE, None)
    if remote is not None:
        remote.begin_check(task)


def pytest_unconfigure(config: pytest.Config) -> None:
    """Write the processor seconds of this judge and of its sandboxes (all closed by now) to
    the file the environment's `TIMES` names, if it names one."""
    path = os.environ.get(TIMES)
    if not path:
        return
    remote = config.stash.get(_REMOTE, None)
    used = resource.getrusage(resource.RUSAGE_SELF)
    times = {
        "judge": used.ru_utime + used.ru_stime,
        "sandboxes": remote.sandbox.used if remote is not None else 0.0,
    }
    Path(path).write_text(json.dumps(times))
