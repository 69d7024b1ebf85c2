"""Fixtures of the journey tests: a person's shell (`shell`)."""

from __future__ import annotations

import sys
from collections.abc import Callable
from pathlib import Path

import pytest
from harness import Typed, typed


@pytest.fixture(scope="session")
def shell() -> Callable[..., Typed]:
    """``shell(command, cwd)``: `harness.typed` in the environment of the Python running
    the tests, as an instructor with msdlab installed types a command line."""
    venv = Path(sys.executable).parent.parent
    return lambda command, cwd, timeout=600: typed(command, cwd, venv, timeout)
