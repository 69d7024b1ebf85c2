"""A big body's threaded step on a busy machine: threads that spin, or threads that sleep?

numba's threads wait for work between the parallel loops of a step. By default (OpenMP's
``OMP_WAIT_POLICY`` unset) a waiting thread spins; on a machine whose cores are busy with
other work (a shared JupyterHub server, a laptop running a browser) the spinning threads
keep the one doing the work off the cores. msdlab's own processes (the command line, a
course notebook's ``Course()``) set ``OMP_WAIT_POLICY=PASSIVE``: waiting threads sleep.

Each measurement is a fresh process (the policy is read when the threads start) that
steps the task 4 notebook's largest body (an 18³ grid with all 26 neighbours, 67 388
springs: the threaded kernel) 3 times untimed, then times 5 batches of 20 steps and
prints their median. The two policies alternate, on a quiet machine and beside ``--hogs``
busy processes (default: twice the cores); the table gives the medians over the repeats.

    python benchmarks/busy_machine.py
    python benchmarks/busy_machine.py --repeats 7 --hogs 4
"""

from __future__ import annotations

import argparse
import os
import statistics
import subprocess
import sys
import time
from contextlib import contextmanager

STEP = """
import statistics, time
import msdlab as msd
body = msd.Body.grid((18, 18, 18), spacing=2 / 18, stiffness=100.0, neighbours=(1, 2, 3))
sim = msd.Simulation(body, msd.Verlet(), 1e-3, [msd.Gravity((0.0, -9.81, 0.0))])
sim.run(steps=3, record_every=3)
batches = []
for _ in range(5):
    start = time.perf_counter()
    sim.run(steps=20, record_every=20)
    batches.append((time.perf_counter() - start) / 20)
print(statistics.median(batches))
"""
POLICIES = ("ACTIVE", "PASSIVE")


def step_time(policy: str) -> float:
    """Seconds a step, median of a fresh process's batches, with ``policy``."""
    env = {**os.environ, "OMP_WAIT_POLICY": policy}
    out = subprocess.run([sys.executable, "-c", STEP], env=env, capture_output=True, text=True)
    if out.returncode:
        raise RuntimeError(out.stderr)
    return float(out.stdout)


@contextmanager
def busy(hogs: int):
    """``hogs`` processes that keep a core busy each, while the block runs."""
    spin = "while True: pass"
    started = [subprocess.Popen([sys.executable, "-c", spin]) for _ in range(hogs)]
    try:
        time.sleep(0.5 if hogs else 0.0)
        yield
    finally:
        for hog in started:
            hog.kill()
            hog.wait()


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--repeats", type=int, default=5)
    parser.add_argument("--hogs", type=int, default=2 * (os.cpu_count() or 1))
    options = parser.parse_args()
    step_time("PASSIVE")  # compiles the loops into numba's cache: not a step's cost
    print(f"{os.cpu_count()} cores; ms a step of an 18³ grid, 67 388 springs; median of "
          f"{options.repeats} alternating runs")  # fmt: skip
    print(f"{'machine':<30}{'spinning':>10}{'sleeping':>10}{'ratio':>8}")
    for label, hogs in (("quiet", 0), (f"beside {options.hogs} busy processes", options.hogs)):
        times: dict[str, list[float]] = {policy: [] for policy in POLICIES}
        with busy(hogs):
            for _ in range(options.repeats):
                for policy in POLICIES:
                    times[policy].append(step_time(policy))
        spinning, sleeping = (1e3 * statistics.median(times[p]) for p in POLICIES)
        print(f"{label:<30}{spinning:>10.2f}{sleeping:>10.2f}{spinning / sleeping:>8.1f}")


if __name__ == "__main__":
    main()
