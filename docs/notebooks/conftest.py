"""pytest runs the notebooks in this folder (built with their outputs by notebooks/build.py)
with nbval, in this Python.

Lax mode: a notebook passes if no cell raises, and the cells marked
``# NBVAL_CHECK_OUTPUT`` print what the saved notebook shows. The options are
set here rather than in pyproject's ``addopts`` because the course's checks run
in pytest processes of their own with nbval switched off (``-p no:nbval``),
where the nbval options would not exist. The saved outputs are those of the
reference answers, so the kernels are asked for them (``MSDLAB_IMPL=solutions``,
unless it is set); a student's run uses their assignments/.
"""

import os
from collections.abc import Iterator

import pytest


def pytest_configure(config: pytest.Config) -> None:
    if not config.pluginmanager.hasplugin("nbval"):
        return
    if not config.option.nbval:  # --nbval (compare every cell) asked for on the command line
        config.option.nbval_lax = True
    config.option.nbval_current_env = True


@pytest.hookimpl(hookwrapper=True)
def pytest_runtest_setup(item: pytest.Item) -> Iterator[None]:
    """A notebook's kernel, started as its first cell is set up, checks the reference answers;
    the variable is set only meanwhile (other tests in this process see the usual default)."""
    with pytest.MonkeyPatch.context() as patch:
        patch.setenv("MSDLAB_IMPL", os.environ.get("MSDLAB_IMPL", "solutions"))
        yield
