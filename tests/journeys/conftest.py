"""Fixtures of the journey tests: a person's shell (`shell`)."""

from __future__ import annotations

import os
import subprocess
import sys
from collections.abc import Callable
from pathlib import Path

import pytest


def typed(command: str, cwd: Path, timeout: float = 600) -> subprocess.CompletedProcess:
    """``command`` run as typed at a shell prompt in ``cwd``, with the environment of this
    Python activated and no msdlab, pytest or Python settings of the process running the
    tests: its exit status, and what it printed (both streams) in ``stdout``."""
    environment = {
        key: value
        for key, value in os.environ.items()
        if not key.startswith(("MSDLAB_", "PYTEST_", "PYTHON"))
    }
    environment["PATH"] = os.pathsep.join([str(Path(sys.executable).parent), os.environ["PATH"]])
    return subprocess.run(
        ["bash", "-c", command],
        cwd=cwd,
        env=environment,
        stdout=subprocess.PIPE,
        stderr=subprocess.STDOUT,
        text=True,
        timeout=timeout,
        check=False,
    )


@pytest.fixture(scope="session")
def shell() -> Callable[..., subprocess.CompletedProcess]:
    """`typed`: ``shell(command, cwd)`` runs a command line as a person types it."""
    return typed
