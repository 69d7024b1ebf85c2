"""How fast does the Warp backend step on a GPU, next to a hand-written gather and to numba?

For a lent machine with an NVIDIA GPU: grids of 60³, 100³ and 200³ particles (√1, √2 and
√3 neighbours, 13 springs a particle, damped Verlet, gravity, the ground, the energy
ledger on) and Warp's cloth (the layout of benchmarks/cloth.py, an edge list), each in
float64 and float32, timed as

- a step: `Simulation.run` with ``record_every`` 100 (a frame, the positions and
  velocities copied to the host, every 100 steps) and 1 (every step), per step;
- a captured frame: the same run with ``sync="frame"``, the 100 steps between two
  recorded frames replayed as one CUDA graph with their sums read back once, per step;
- the reference: a hand-written gather written here as one plain Warp kernel (each
  particle sums its 26 neighbours' springs and steps itself, no ledger, no checks), the
  speed of light of this step on the device, per step;
- the numba backend on all the machine's cores, per step, float64.

Before timing, the Warp backend's float64 run is checked against numba's (the same 20 steps
of the smallest grid, to rounding). Goals on an H100: the Warp step within 2× of the
reference at 100³ float64, and at least 100× the numba step on all cores at 200³.

    python benchmarks/gpu.py              # on a GPU, under 5 minutes
    python benchmarks/gpu.py --quick      # small sizes, on Warp's CPU device if no GPU

Warp is an optional dependency (``pip install -e ".[bench]"``).
"""

from __future__ import annotations

import argparse
import os
import statistics
import time
from collections.abc import Callable

import numpy as np
import warp as wp

import msdlab as msd
from msdlab.engine.backends.process import configure_process
from msdlab.engine.backends.warp import WarpKernel

configure_process()  # the process settings of the command line

SPACING = 0.01  # m
STIFFNESS = 2000.0  # N/m
DT = 2e-5  # s, well inside the stable step of these grids
PRECISIONS = ("float64", "float32")


def grid_simulation(n: int, kernel: WarpKernel | str) -> msd.Simulation:
    """An n³ jelly grid resting just above the ground, in gravity, damped Verlet, ledger on."""
    body = msd.Body.grid((n, n, n), spacing=SPACING, stiffness=STIFFNESS, neighbours=(1, 2, 3))
    body.positions[:, 1] += 0.001
    body.velocities[:, 0] = 0.01
    forces = [msd.Gravity((0.0, -9.81, 0.0)), msd.Ground()]
    name = kernel if isinstance(kernel, str) else "numpy"
    return on(kernel, msd.Simulation(body, msd.Verlet(damping=0.001), DT, forces, kernel=name))


def on(kernel: WarpKernel | str, sim: msd.Simulation) -> msd.Simulation:
    """``sim`` stepping on ``kernel``: a WarpKernel of a chosen device and precision."""
    if not isinstance(kernel, str):
        sim.dynamics.chosen = sim.dynamics.springs = kernel
    return sim


def cloth_simulation(n: int, kernel: WarpKernel | str) -> msd.Simulation:
    """benchmarks/cloth.py's cloth: an edge list of stretch, shear and bend springs."""
    from cloth import msdlab_cloth

    return on(kernel, msdlab_cloth(n, kernel if isinstance(kernel, str) else "numpy"))


def per_step(run: Callable[[], None], steps: int, repeats: int) -> float:
    """Median ms per step of ``run`` (which takes ``steps`` steps), after one warm-up run."""
    run()
    times = []
    for _ in range(repeats):
        start = time.perf_counter()
        run()
        times.append((time.perf_counter() - start) / steps * 1e3)
    return statistics.median(times)


def backend_times(make: Callable, n: int, device: str, precision: str, repeats: int) -> dict:
    """ms per step of the Warp backend: runs recording every 100 steps (synced every step,
    and every frame) and every step."""
    sim = make(n, WarpKernel(device, precision))
    few = 3 if n >= 150 else 20  # a frame each step copies the whole state

    def run(steps: int, every: int, sync: str = "step") -> float:
        return per_step(lambda: sim.run(steps, record_every=every, sync=sync), steps, repeats)

    return {"record 100": run(100, 100), "record 1": run(few, 1), "frame": run(100, 100, "frame")}


def reference_kernel(scalar: type) -> object:
    """The hand-written gather: one thread per particle of an n³ grid sums the springs to its
    26 neighbours (rest length by offset) and takes a symplectic Euler step with gravity."""
    vector = wp.types.vector(3, scalar)

    @wp.kernel(module="unique", enable_backward=False)
    def gather_step(
        x: wp.array(dtype=vector),
        v: wp.array(dtype=vector),
        n: int,
        k: scalar,
        h: scalar,
        inverse_mass: scalar,
        dt: scalar,
        x_new: wp.array(dtype=vector),
        v_new: wp.array(dtype=vector),
    ):
        i = wp.tid()
        a, b, c = i // (n * n), (i // n) % n, i % n
        f = vector()
        for o in range(27):
            p, q, r = a + o // 9 - 1, b + (o // 3) % 3 - 1, c + o % 3 - 1
            if o != 13 and p >= 0 and p < n and q >= 0 and q < n and r >= 0 and r < n:
                d = x[i] - x[(p * n + q) * n + r]
                squared = wp.abs(o // 9 - 1) + wp.abs((o // 3) % 3 - 1) + wp.abs(o % 3 - 1)
                rest = h * wp.sqrt(scalar(squared))  # |offset|·h
                length = wp.length(d)
                f = f + d * (k * (rest - length) / length)
        u = v[i] + dt * (f * inverse_mass + vector(scalar(0.0), scalar(-9.81), scalar(0.0)))
        v_new[i] = u
        x_new[i] = x[i] + dt * u

    return gather_step


def reference_time(n: int, device: str, precision: str, repeats: int) -> float:
    """ms per step of the hand-written gather, state_0/state_1 swapped, 100 steps a run."""
    scalar = wp.float64 if precision == "float64" else wp.float32
    vector = wp.types.vector(3, scalar)
    kernel = reference_kernel(scalar)
    x = msd.engine.model.lattice.grid_positions((n, n, n), SPACING).astype(scalar._type_)
    states = [wp.array(x, dtype=vector, device=device), wp.zeros(n**3, vector, device=device)]
    states += [wp.empty_like(states[0]), wp.empty_like(states[1])]
    numbers = (n, scalar(STIFFNESS), scalar(SPACING), scalar(1.0), scalar(DT))

    def run() -> None:
        for step in range(100):
            x, v, x_new, v_new = states if step % 2 == 0 else states[2:] + states[:2]
            wp.launch(kernel, n**3, [x, v, *numbers, x_new, v_new], device=device)
        wp.synchronize_device(device)

    return per_step(run, 100, repeats)


def numba_time(make: Callable, n: int, repeats: int) -> float:
    """ms per step of the numba backend on all cores, recording every 100 steps."""
    sim = make(n, "numba")
    steps = 5 if n >= 150 else 50
    return per_step(lambda: sim.run(steps=steps, record_every=steps), steps, repeats)


def check_agreement(n: int, device: str) -> str:
    """The Warp backend's float64 grid against numba's after 20 steps, or SystemExit."""
    sims = [grid_simulation(n, WarpKernel(device, "float64")), grid_simulation(n, "numba")]
    for sim in sims:
        sim.run(steps=20, record_every=20)
    gap = float(np.abs(sims[0].body.positions - sims[1].body.positions).max())
    if not gap <= 1e-12:
        raise SystemExit(f"{n}³: the Warp backend is {gap:.1e} m from numba after 20 steps")
    return f"{n}³ grid, 20 steps: {gap:.1e} m from numba"


def table(sizes: dict, device: str, repeats: int) -> list[dict]:
    """Time every body of ``sizes`` (name: (make, n)) in both precisions; print a row each."""
    print("| body | precision | record 100 | record 1 | frame | reference | numba | ref. ratio |")
    print("| --- | --- | --- | --- | --- | --- | --- | --- |")
    rows = []
    for name, (make, n) in sizes.items():
        cores = numba_time(make, n, repeats)
        for precision in PRECISIONS:
            times = backend_times(make, n, device, precision, repeats)
            grid = make is grid_simulation
            reference = reference_time(n, device, precision, repeats) if grid else float("nan")
            rows.append({"body": name, "n": n, "precision": precision, **times})
            rows[-1].update(reference=reference, numba=cores)
            cells = [f"{times[k]:.3f}" for k in ("record 100", "record 1", "frame")]
            ratio = times["record 100"] / reference if grid else float("nan")
            print(
                f"| {name} | {precision} | {' | '.join(cells)} | {reference:.3f} | "
                f"{cores:.3f} | {ratio:.2f} |"
            )
    return rows


def goals(rows: list[dict], large: str, medium: str) -> None:
    """The issue's two goals, measured: within 2× of the reference at the medium grid, and
    100× the numba step at the large one (float64)."""
    f64 = {row["body"]: row for row in rows if row["precision"] == "float64"}
    ratio = f64[medium]["record 100"] / f64[medium]["reference"]
    speedup = f64[large]["numba"] / f64[large]["record 100"]
    print(f"\n{medium} float64: the Warp step is {ratio:.2f}× the hand-written gather (goal ≤ 2)")
    print(f"{large} float64: the Warp step is {speedup:.3g}× numba on all cores (goal ≥ 100)")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="small sizes, a run of seconds")
    parser.add_argument("--repeats", type=int, default=5)
    args = parser.parse_args()
    wp.config.log_level = wp.LOG_WARNING
    device = "cuda" if wp.get_cuda_device_count() > 0 else "cpu"
    grids, cloth = ((6, 10, 14), 16) if args.quick else ((60, 100, 200), 128)
    repeats = 1 if args.quick else args.repeats
    print(f"device {wp.get_device(device).name}; {os.cpu_count()} cores for numba")
    print(check_agreement(grids[0], device))
    sizes = {f"{n}³ grid": (grid_simulation, n) for n in grids}
    sizes[f"cloth {cloth}×{cloth}"] = (cloth_simulation, cloth)
    print(f"\nms per step, median of {repeats}")
    rows = table(sizes, device, repeats)
    goals(rows, f"{grids[2]}³ grid", f"{grids[1]}³ grid")


if __name__ == "__main__":
    main()
