"""How fast is a user's integrator next to `msd.Verlet`, on a 30³ grid?

Three integrators step the same body (30³ grid, neighbours 1, 2, 3, k = 100 N/m,
gravity, ground, ledger on) with the default kernel:

- ``msd.Verlet(0.01)``, the engine's;
- ``advance``: a user's subclass of `msd.Integrator` whose update is a plain
  function handed to ``dynamics.advance`` (the documented way; compiled);
- ``arrays``: task 5's reference `DampedVerlet`, written with
  ``dynamics.acceleration`` and numpy array operations (runs as written).

The machine is shared, so the three run interleaved in batches of about
0.15 s; a ratio is a user's batch over the engine's batch next to it, median
and range over the repeats.

``--parts`` times task 5's step by parts instead: its ``dynamics.acceleration``
and its own array operations (its ``step`` given an acceleration made before),
each alone, plus what `Simulation.step` adds to ``msd.Verlet``'s own step
(constraints, ledger, divergence check, storing). Their sum over ``msd.Verlet``
is the ratio task 5 would have if its parts ran inside the step as fast as
alone, i.e. without what they evict from each other's cache; the array
operations are also timed right after writing 2, 4 and 6 MiB elsewhere.

    python benchmarks/user_integrator.py [--n 30] [--repeats 9] [--parts]
"""

from __future__ import annotations

import argparse
import importlib.util
import time
from collections.abc import Callable
from pathlib import Path

import numpy as np

import msdlab as msd
from msdlab.engine.backends.process import configure_process

configure_process()  # the process settings of the command line

SOLUTION = Path(__file__).resolve().parents[1] / "solutions" / "task5.py"


def damped_verlet_update(
    x: float, v: float, a: float, dt: float, damping: float
) -> tuple[float, float]:
    """Eq. (1.4) as a user writes it: x(t + dt) = x + (1 - λ)(x - x(t - dt)) + a dt²."""
    x_new = x + (1.0 - damping) * v * dt + a * dt * dt
    return x_new, (x_new - x) / dt


class UserVerlet(msd.Integrator):
    """A user's damped Verlet through ``dynamics.advance`` (compiled by the kernel)."""

    def __init__(self, damping: float) -> None:
        self.damping = damping

    def step(self, x: np.ndarray, v: np.ndarray, dt: float, dynamics: msd.Dynamics):
        return dynamics.advance(damped_verlet_update, x, v, dt, self.damping)


def task5_damped_verlet() -> type[msd.Integrator]:
    """The reference solution of task 5 (array operations)."""
    spec = importlib.util.spec_from_file_location("task5_solution", SOLUTION)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module.DampedVerlet


def simulation(n: int, integrator: msd.Integrator) -> msd.Simulation:
    body = msd.Body.grid((n, n, n), spacing=1.0, stiffness=100.0, neighbours=(1, 2, 3))
    body.positions[:, 1] += 0.5  # just above the ground
    forces = [msd.Gravity((0.0, -9.81, 0.0)), msd.Ground(height=0.0)]
    return msd.Simulation(body, integrator, dt=1e-3, forces=forces)


def batch_time(step: Callable[[], None], steps: int) -> float:
    """Seconds per step over ``steps`` steps."""
    start = time.perf_counter()
    for _ in range(steps):
        step()
    return (time.perf_counter() - start) / steps


class GivenAcceleration:
    """Stands for `msd.Dynamics` with an acceleration (m/s²) computed before."""

    def __init__(self, acceleration: np.ndarray) -> None:
        self.given = acceleration

    def acceleration(self, x: np.ndarray, v: np.ndarray) -> np.ndarray:
        return self.given


def timed_after(write: np.ndarray, call: Callable[[], object]) -> Callable[[], float]:
    """``call``, after writing the whole of ``write`` (evicting that much of the cache);
    returns the seconds ``call`` took."""

    def write_then_call() -> float:
        write.fill(1.0)
        start = time.perf_counter()
        call()
        return time.perf_counter() - start

    return write_then_call


VERLET_STEP = "msd.Verlet: Simulation.step"
VERLET_ALONE = "msd.Verlet: its step alone"
TASK5_STEP = "task 5: Simulation.step"
TASK5_ACCELERATION = "task 5: dynamics.acceleration"
TASK5_OPS = "task 5: its array operations"


def parts(n: int, repeats: int) -> None:
    """Print where task 5's step goes, next to a whole `msd.Verlet` step (ms, medians)."""
    engine, task5 = simulation(n, msd.Verlet(0.01)), simulation(n, task5_damped_verlet()(0.01))
    for sim in (engine, task5):
        sim.step()
    body, dynamics = task5.body, task5.dynamics
    given = GivenAcceleration(dynamics.acceleration(body.positions, body.velocities))
    steps = max(3, round(0.15 / batch_time(engine.step, 3)))

    def alone(sim: msd.Simulation, dynamics: object) -> Callable[[], object]:
        state = (sim.body.positions, sim.body.velocities)
        return lambda: sim.integrator.step(*state, sim.dt, dynamics)

    timed = {
        VERLET_STEP: engine.step,
        VERLET_ALONE: alone(engine, engine.dynamics),
        TASK5_STEP: task5.step,
        TASK5_ACCELERATION: lambda: dynamics.acceleration(body.positions, body.velocities),
        TASK5_OPS: alone(task5, given),
    }
    written = {f"  after writing {mib} MiB": mib * 2**20 // 8 for mib in (2, 4, 6)}
    buffer = np.zeros(max(written.values()))
    times: dict[str, list[float]] = {name: [] for name in (*timed, *written)}
    for _ in range(repeats):
        for name, call in timed.items():
            times[name].append(batch_time(call, steps))
        for name, size in written.items():
            call = timed_after(buffer[:size], timed[TASK5_OPS])
            times[name].append(float(np.mean([call() for _ in range(steps)])))
    print(f"{n}³ grid, {body.n_springs:,} springs, {steps} steps per batch, ms (medians)")
    print_parts({name: 1e3 * float(np.median(values)) for name, values in times.items()})


def print_parts(ms: dict[str, float]) -> None:
    """Print `parts`' times (ms) and task 5's ratio to `msd.Verlet`, whole and by parts."""
    verlet = ms[VERLET_STEP]
    rest = verlet - ms[VERLET_ALONE]  # constraints, ledger, check, store
    by_parts = ms[TASK5_ACCELERATION] + ms[TASK5_OPS] + rest
    for name, value in ms.items():
        print(f"{name:<32} {value:6.3f}")
    print(f"{'task 5 parts + msd.Verlet rest':<32} {by_parts:6.3f}")
    print(
        f"task 5 ÷ msd.Verlet {ms[TASK5_STEP] / verlet:.2f}; "
        f"its parts timed alone {by_parts / verlet:.2f}"
    )


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--n", type=int, default=30)
    parser.add_argument("--repeats", type=int, default=9)
    parser.add_argument("--parts", action="store_true", help="split task 5's step")
    args = parser.parse_args()
    if args.parts:
        parts(args.n, args.repeats)
        return
    contenders = {
        "msd.Verlet(0.01)": simulation(args.n, msd.Verlet(0.01)),
        "advance (user)": simulation(args.n, UserVerlet(0.01)),
        "arrays (task 5)": simulation(args.n, task5_damped_verlet()(0.01)),
    }
    for sim in contenders.values():  # compile and warm up
        sim.step()
    engine = contenders["msd.Verlet(0.01)"]
    steps = max(3, round(0.15 / batch_time(engine.step, 3)))
    times: dict[str, list[float]] = {name: [] for name in contenders}
    for _ in range(args.repeats):
        for name, sim in contenders.items():
            times[name].append(batch_time(sim.step, steps))
    engine_times = np.array(times["msd.Verlet(0.01)"])
    print(f"{args.n}³ grid, {engine.body.n_springs:,} springs, {steps} steps per batch")
    print(f"{'integrator':<18} {'ms/step':>8} {'÷ Verlet':>9}  range")
    for name, values in times.items():
        ratio = np.array(values) / engine_times
        print(
            f"{name:<18} {1e3 * np.median(values):8.2f} {np.median(ratio):9.2f}  "
            f"{ratio.min():.2f}–{ratio.max():.2f}"
        )


if __name__ == "__main__":
    main()
