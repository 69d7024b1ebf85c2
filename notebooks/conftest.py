"""pytest runs the notebooks in this folder with nbval, in this Python.

Lax mode: a notebook passes if no cell raises, and the cells marked
``# NBVAL_CHECK_OUTPUT`` print what the saved notebook shows. The options are
set here rather than in pyproject's ``addopts`` because the course's checks run
in pytest processes of their own with nbval switched off (``-p no:nbval``),
where the nbval options would not exist.
"""

import pytest


def pytest_configure(config: pytest.Config) -> None:
    if not config.pluginmanager.hasplugin("nbval"):
        return
    if not config.option.nbval:  # --nbval (compare every cell) asked for on the command line
        config.option.nbval_lax = True
    config.option.nbval_current_env = True
