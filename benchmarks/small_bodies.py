"""What does a step of a small body cost? Microseconds per `Simulation.step` of a jelly cube.

An n³ cube (``Body.grid``, 13 springs per particle, k = 5000 N/m, 0.1 m apart)
resting on the ground, stepped with ``Verlet(0.01)``, gravity, ``Ground`` and the
energy ledger, as the course's scenes and the live view run it. For such bodies
the compiled work is a few microseconds and the rest is the fixed toll of a step:
Python calls, numpy calls on a few rows, the ledger. Each size is timed in batches
of about 0.1 s, repeated; the table shows the median and the fastest batch, and
the share of `Ground.apply` (timed alone on the same state).

    python benchmarks/small_bodies.py                  # n = 4, 8 on the numba kernel
    python benchmarks/small_bodies.py --n 4 6 8 12 --kernel numpy
"""

from __future__ import annotations

import argparse
import statistics
import time

BATCH_S = 0.1
TARGETS_US = {4: 40.0, 8: 60.0}  # the engine's goals on the numba kernel


def resting_cube(n: int, kernel: str):
    """A `Simulation` of an n³ jelly cube that has settled on the ground."""
    import msdlab as msd

    cube = msd.Body.grid((n, n, n), spacing=0.1, stiffness=5000.0, neighbours=(1, 2, 3))
    forces = [msd.Gravity((0.0, -9.81, 0.0)), msd.Ground(height=0.0)]
    sim = msd.Simulation(cube, msd.Verlet(0.01), dt=1e-3, forces=forces, kernel=kernel)
    sim.run(steps=300)  # compiled, and resting on the ground
    return sim


def batches_us(run_once, repeats: int) -> list[float]:
    """Microseconds per call of ``run_once`` in ``repeats`` batches of about `BATCH_S`."""
    start, count = time.perf_counter(), 0
    while time.perf_counter() - start < BATCH_S / 4:
        run_once()
        count += 1
    per_batch = max(1, round(count * 4))
    times = []
    for _ in range(repeats):
        start = time.perf_counter()
        for _ in range(per_batch):
            run_once()
        times.append((time.perf_counter() - start) / per_batch * 1e6)
    return times


def ground_alone(sim):
    """`Ground.apply` on the state a step of ``sim`` reaches, run again and again."""
    from msdlab import StepState

    body, ground = sim.body, sim.constraints[0]
    x, v = body.positions, body.velocities
    step = sim.dynamics.step(sim.integrator, x, v, sim.dt)
    x_new, v_new = step.x, step.v
    arrays = (x, v, x_new.copy(), v_new.copy())
    state = StepState(body, *arrays, sim.time, sim.dt, lambda p: 0.0, sim.dynamics.springs)

    def apply() -> None:
        state.x[...] = x_new
        state.v[...] = v_new
        ground.apply(state)

    return apply


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--n", type=int, nargs="+", default=[4, 8])
    parser.add_argument("--kernel", choices=("numba", "numpy"), default="numba")
    parser.add_argument("--repeats", type=int, default=9)
    args = parser.parse_args()

    from msdlab.engine.backends.process import configure_process

    configure_process()
    print(f"{args.kernel} kernel, Verlet(0.01), gravity, ground, ledger; µs per step")
    print("| n | particles | springs | median | fastest | Ground.apply | goal |")
    print("| --- | --- | --- | --- | --- | --- | --- |")
    for n in args.n:
        sim = resting_cube(n, args.kernel)
        steps = batches_us(sim.step, args.repeats)
        ground = batches_us(ground_alone(sim), args.repeats)
        goal = TARGETS_US.get(n) if args.kernel == "numba" else None
        print(
            f"| {n} | {len(sim.body)} | {sim.body.n_springs} | {statistics.median(steps):.1f} "
            f"| {min(steps):.1f} | {statistics.median(ground):.1f} "
            f"| {'-' if goal is None else f'<= {goal:g}'} |"
        )


if __name__ == "__main__":
    main()
