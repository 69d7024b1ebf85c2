"""The seeds' scenes on the Warp backend, on Warp's CPU device where no GPU is lent.

The scenes whose steps run whole on a device (a jelly cube on the ground, a cloth in
gravity) pass their own tests on it: the same tests at the same tolerances, in a pytest run
of their own with ``MSDLAB_KERNEL=warp`` (their module fixtures then step on Warp too). The
trampoline, whose ball meets the net through a contact force the host adds every step,
runs its first 0.6 s (the ball falls, lands and sinks into the net) on Warp as on numba;
its whole tests take about 5 minutes there, too long for CI."""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
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


TRAMPOLINE = """
import json
from msdlab.scenes.trampoline import trampoline
run = trampoline().run(duration=0.6, record_every=50)
print(json.dumps({"x": run.positions.tolist(), "drift": run.energies.drift.tolist()}))
"""


def trampoline_on(kernel: str) -> dict:
    """The trampoline's first 0.6 s stepped with ``kernel``, in a process of its own."""
    run = subprocess.run(
        [sys.executable, "-c", TRAMPOLINE],
        env={**os.environ, "MSDLAB_KERNEL": kernel},
        capture_output=True,
        text=True,
        timeout=600,
    )
    assert run.returncode == 0, run.stderr[-3000:]
    return json.loads(run.stdout)


def test_the_trampolines_ball_lands_on_warp_as_on_numba() -> None:
    pytest.importorskip("warp")
    warp, numba = trampoline_on("warp"), trampoline_on("numba")
    ball = np.asarray(numba["x"])[:, -1, 2]
    assert ball.min() < 0.5  # the ball (radius 0.5 m) reached the net at z = 0
    np.testing.assert_allclose(warp["x"], numba["x"], rtol=0, atol=1e-12)  # m
    np.testing.assert_allclose(warp["drift"], numba["drift"], rtol=0, atol=1e-10)  # J
