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
