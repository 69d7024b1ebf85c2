"""Shared test settings, and how the tests are shared between pytest-xdist workers."""

from __future__ import annotations

import os
from pathlib import PurePosixPath

import pytest
from hypothesis import settings

settings.register_profile("ci", deadline=None, max_examples=50, print_blob=True)
settings.load_profile("ci")


@pytest.hookimpl(tryfirst=True)  # before the course plugin reads the choice
def pytest_configure(config: pytest.Config) -> None:
    """The project's tests check the reference answers: the course checks run in this
    process (tests/tasks) are asked for solutions/ unless --impl or $MSDLAB_IMPL chose."""
    if config.pluginmanager.hasplugin("msdlab") and not (
        config.getoption("impl") or os.environ.get("MSDLAB_IMPL")
    ):
        config.option.impl = "solutions"


# Folders whose test files share a session fixture: the built docs site, a Dask scheduler.
SHARED = {"tests/docs", "tests/scale"}

# The longest files (and the docs folder), handed to the workers first: a file of 6 minutes
# started last keeps one worker busy after the other has run out of work.
FIRST = (
    "tests/journeys/test_documented_commands.py",
    "tests/docs/",
    "tests/course/test_grading_matrix.py",
    "tests/journeys/",
)


def pytest_collection_modifyitems(items: list[pytest.Item]) -> None:
    """The files of `FIRST` first, in its order; the rest as collected."""

    def rank(item: pytest.Item) -> int:
        return next(
            (i for i, start in enumerate(FIRST) if item.nodeid.startswith(start)), len(FIRST)
        )

    items.sort(key=rank)


@pytest.hookimpl(optionalhook=True)
def pytest_xdist_make_scheduler(config: pytest.Config, log: object) -> object:
    """``pytest -n N``: a worker takes a whole file (its module fixtures are made once, a
    notebook's cells run in order), or all the files of a `SHARED` folder."""
    from xdist.scheduler import LoadScopeScheduling

    class ByFile(LoadScopeScheduling):
        def _split_scope(self, nodeid: str) -> str:
            path = PurePosixPath(nodeid.split("::", 1)[0])
            return str(path.parent) if str(path.parent) in SHARED else str(path)

    return ByFile(config, log)
