"""The seeds' scenes whose steps run whole on a device (a jelly cube on the ground, a cloth
in gravity) pass their own tests on the Warp backend, on Warp's CPU device where no GPU is
lent: the same tests at the same tolerances, in a pytest run of their own with
``MSDLAB_KERNEL=warp`` (their module fixtures then step on Warp too)."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest

HERE = Path(__file__).resolve().parent
SCENES = ("test_jelly.py", "test_cloth.py")


def test_the_jelly_and_cloth_scenes_pass_on_warp() -> None:
    pytest.importorskip("warp")
    command = [sys.executable, "-m", "pytest", "-p", "no:xdist", "-q", "-p", "no:cacheprovider"]
    environment = {**os.environ, "MSDLAB_KERNEL": "warp"}
    run = subprocess.run(
        [*command, *(str(HERE / name) for name in SCENES)],
        env=environment,
        capture_output=True,
        text=True,
        cwd=HERE.parents[1],
        timeout=600,
    )
    assert run.returncode == 0, run.stdout[-4000:] + run.stderr[-2000:]
    assert " passed" in run.stdout and "skipped" not in run.stdout
