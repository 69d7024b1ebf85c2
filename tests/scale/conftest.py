"""Shared by the course-scale tests: a small check set (task 1's public and hidden checks),
so each grading takes seconds while exercising the same judge, sandbox and report."""

from __future__ import annotations

import shutil
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
