"""Shared by the course-scale tests: a small check set (task 1's public and hidden checks),
so each grading takes seconds while exercising the same judge, sandbox and report."""

from __future__ import annotations

import shutil
from collections.abc import Iterator
from pathlib import Path

import pytest

from msdlab.course import PROJECT_ROOT

CHECK_FILES = ("conftest.py", "reference_hidden.py", "test_task1.py", "test_task1_hidden.py")


@pytest.fixture(scope="session")
def task1_checks(tmp_path_factory: pytest.TempPathFactory) -> Path:
    folder = tmp_path_factory.mktemp("checks")
    for name in CHECK_FILES:
        shutil.copyfile(PROJECT_ROOT / "tests" / "tasks" / name, folder / name)
    return folder


@pytest.fixture(scope="session")
def scheduler() -> Iterator[str]:
    """The address of a Dask scheduler with one worker process of one thread."""
    distributed = pytest.importorskip("dask.distributed", reason="needs msdlab[cluster]")
    options = dict(n_workers=1, threads_per_worker=1, dashboard_address=None, memory_limit=0)
    with distributed.LocalCluster(processes=True, **options) as cluster:
        yield cluster.scheduler_address
