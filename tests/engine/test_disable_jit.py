"""``NUMBA_DISABLE_JIT=1`` runs the numba kernel's loops as plain Python, with the same results.

That is how one steps through the compiled loops with a debugger or prints inside
them; the test runs the same steps compiled and not, on every path of the kernel.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys

import numpy as np
import pytest

RUN = """
import json, sys
import numba
import numpy as np
import msdlab as msd
from msdlab.engine.backends.numba import kernel

if sys.argv[1] == "threads":  # every loop on its threaded variant
    for limit in ("PARALLEL_MIN_SPRINGS", "PARALLEL_MIN_GATHERED", "PARALLEL_MIN_PARTICLES"):
        setattr(kernel, limit, 0)
results = {}
for name, shuffled, dim in (("grid 3-D", False, 3), ("edges 3-D", True, 3), ("grid 2-D", False, 2)):
    shape = (4, 3, 5) if dim == 3 else (6, 5)
    body = msd.Body.grid(shape, stiffness=40.0, neighbours=(1, 2), damping=0.2)
    if shuffled:  # the same springs in another order: not a grid
        order = np.random.default_rng(0).permutation(body.n_springs)
        pairs = np.stack([body.edges().a, body.edges().b], axis=1)[order]
        body = msd.Body.from_arrays(body.positions, pairs, stiffness=40.0, damping=0.2)
    body.positions[:, 1] += 0.5
    body.fixed[0] = True
    g = (0.0, -9.81, 0.0)[:dim]
    sim = msd.Simulation(
        body, msd.Verlet(0.01), dt=0.01, forces=[msd.Gravity(g), msd.Ground()], kernel="numba"
    )
    run = sim.run(steps=40, record_every=40)
    lattice = type(body.spring_set).__name__ == "LatticeSprings"  # gathered, not edge by edge
    results[name] = [body.positions.tolist(), run.energies.total.tolist(), lattice]
print(json.dumps({"compiled": not numba.config.DISABLE_JIT, "runs": results}))
"""


def run(threads: bool, disable_jit: bool) -> dict:
    env = {**os.environ, "NUMBA_DISABLE_JIT": "1" if disable_jit else "0"}
    mode = "threads" if threads else "one"
    result = subprocess.run(
        [sys.executable, "-c", RUN, mode], env=env, capture_output=True, text=True, timeout=600
    )
    assert result.returncode == 0, result.stderr
    output = json.loads(result.stdout)
    assert output["compiled"] is not disable_jit
    return output["runs"]


@pytest.mark.parametrize("threads", [False, True], ids=["one thread", "threads"])
def test_the_loops_run_as_python_with_the_same_results(threads: bool, kernel: str) -> None:
    if kernel == "numpy":
        pytest.skip("the numba kernel's loops")
    compiled, python = run(threads, disable_jit=False), run(threads, disable_jit=True)
    assert compiled.keys() == python.keys() == {"grid 3-D", "edges 3-D", "grid 2-D"}
    for name, (positions, energies, gathered) in compiled.items():
        assert gathered == python[name][2] == name.startswith("grid")
        np.testing.assert_allclose(python[name][0], positions, rtol=0, atol=1e-12, err_msg=name)
        np.testing.assert_allclose(python[name][1], energies, rtol=1e-12, err_msg=name)
        assert min(row[1] for row in positions) < 0.5  # it fell onto the ground
