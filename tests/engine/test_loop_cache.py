"""The integrators' update loops are compiled once per machine, not once per process."""

from __future__ import annotations

import json
import os
import subprocess
import sys

import pytest

import msdlab as msd
from msdlab.engine.backends.numba import kernel as numba_kernel

# A process steps a small cube once and reports, for its Verlet update loop, how many
# signatures numba compiled and how many it loaded from its disk cache.
STEP_ONCE = """
import json
import msdlab as msd
from msdlab.engine.backends.numba import kernel
cube = msd.Body.grid((3, 3, 3), spacing=0.1, stiffness=500.0)
msd.Simulation(cube, msd.Verlet(0.01), dt=1e-3, forces=[msd.Gravity((0, -9.81, 0))]).step()
(loop,) = [f for (update, _), f in kernel._LOOPS.items() if update is msd.Verlet.update]
print(json.dumps({"misses": sum(loop.stats.cache_misses.values()),
                  "hits": sum(loop.stats.cache_hits.values())}))
"""


def step_once(cache) -> dict[str, int]:
    environment = {**os.environ, "NUMBA_CACHE_DIR": str(cache), "MSDLAB_KERNEL": "numba"}
    done = subprocess.run(
        [sys.executable, "-c", STEP_ONCE], env=environment, capture_output=True, text=True
    )
    assert done.returncode == 0, done.stderr
    return json.loads(done.stdout.splitlines()[-1])


def test_a_second_process_loads_the_verlet_loop_compiled(tmp_path, kernel):
    if kernel != "numba":
        pytest.skip("the numba kernel's loops")
    first, second = step_once(tmp_path), step_once(tmp_path)
    assert first == {"misses": 1, "hits": 0}
    assert second == {"misses": 0, "hits": 1}


def test_a_users_update_is_compiled_in_its_process_only():
    """numba keys a cached loop by the update's code, not by what it calls, which a user's
    module may change; msdlab's own updates call nothing."""

    def user_update(x, v, a, dt):
        return x + dt * v, v + dt * a

    assert not numba_kernel.cached(user_update)
    assert numba_kernel.cached(msd.Verlet.update)


# A process compiles Verlet's update loop, threaded or not, on a small state, and reports
# whether numba loaded it from its disk cache.
COMPILE_ONE = """
import json, sys
import numpy as np
import msdlab as msd
from msdlab.engine.backends.numba.kernel import compile_advance
loop = compile_advance(msd.Verlet.update, threads=sys.argv[1] == "threads")
x = np.zeros((4, 3))
loop(x, x, x, np.zeros((0, 4, 3)), np.zeros(3), np.ones(4), np.zeros(4, bool), 1e-3, (0.01,),
     np.empty_like(x), np.empty_like(x))
print(json.dumps(sum(loop.stats.cache_hits.values())))
"""


def test_the_threaded_and_the_one_thread_loop_are_cached_apart(tmp_path, kernel):
    """A one-thread loop is never the threaded loop loaded from the cache (that one costs a
    wake-up of the threads on every call, 20 µs on a small body)."""
    if kernel != "numba":
        pytest.skip("the numba kernel's loops")
    environment = {**os.environ, "NUMBA_CACHE_DIR": str(tmp_path)}
    hits = []
    for kind in ("threads", "one thread", "one thread"):
        done = subprocess.run(
            [sys.executable, "-c", COMPILE_ONE, kind],
            env=environment,
            capture_output=True,
            text=True,
        )
        assert done.returncode == 0, done.stderr
        hits.append(json.loads(done.stdout.splitlines()[-1]))
    assert hits == [0, 0, 1]
