"""How fast does msdlab step a big body? Prints a table comparing implementations.

Workload: an n×n×n grid with neighbours (1, 2, 3) (13 springs per particle),
spacing 2/n, origin (-1, 1.5, -1), k = 50 N/m, m = 1 kg, gravity, ground at
y = 0 (not reached during the measured steps), dt = 1 ms, one step at a time.

Implementations, each run in its own process (so its peak memory is its own):

- engine: `msdlab.Simulation.step` with the compiled kernel, Verlet(λ = 0.01)
  and SymplecticEuler: the full step (forces, integrator, fixed particles,
  ground, energy ledger, divergence check);
- engine, numpy kernel: the same step with ``kernel="numpy"``;
- numpy edge list: a plain numpy Verlet step over the spring list (gravity,
  ground clamp, nothing else), what one writes without an engine;
- Spring.force loop: a Python loop over ``body.springs`` calling
  `Spring.force`, timed on a sample of springs and scaled to all of them.

Columns: ms/step is the median of the timed steps after warm-up; M upd/s is
million spring updates per second (springs / time per step); step MiB is the
peak of memory allocated during one step (tracemalloc, i.e. temporaries and
new arrays, not the body already built); peak RSS is the process's maximum
resident memory (getrusage: Python, libraries, the body and the steps);
build s is the time of `Body.grid`.

    python benchmarks/step_speed.py                 # n = 20, 40, 60, 100
    python benchmarks/step_speed.py --n 20 40 --repeats 5
    python benchmarks/step_speed.py --skip-100      # without the 1 M particle grid

It ends with the ImplicitEuler step on a 20³ grid and 10 000 steps of a small
2-D body, in the air and resting on the ground (where the ground's energy
bookkeeping runs every step).
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import resource
import subprocess
import sys
import tempfile
import time
import tracemalloc

import numpy as np

import msdlab as msd
from msdlab.cli import configure_process

configure_process()  # the thread wait policy the command line uses

IMPLEMENTATIONS = {
    "engine-verlet": "engine, numba, Verlet",
    "engine-symplectic": "engine, numba, SymplecticEuler",
    "engine-numpy": "engine, numpy kernel, Verlet",
    "user-arrays": "engine, numba, a user's Verlet on arrays",
    "user-advance": "engine, numba, a user's Verlet via advance",
    "numpy-edge-list": "numpy edge list, Verlet",
    "spring-loop": "Spring.force loop, Verlet",
}
DT = 1e-3
GRAVITY = (0.0, -9.81, 0.0)
LOOP_SAMPLE = 20_000  # springs timed for the Spring.force loop


def make_grid(n: int) -> tuple[msd.Body, float]:
    """The benchmark body and the seconds `Body.grid` took."""
    start = time.perf_counter()
    body = msd.Body.grid(
        (n, n, n), spacing=2.0 / n, stiffness=50.0, neighbours=(1, 2, 3), origin=(-1, 1.5, -1)
    )
    return body, time.perf_counter() - start


def damped_verlet_update(
    x: np.ndarray, v: np.ndarray, a: np.ndarray, dt: float, lam: float
) -> tuple[np.ndarray, np.ndarray]:
    """Eq. (1.4) as a user writes it (like task 5), for numbers or arrays."""
    old = x - v * dt
    new = (2.0 - lam) * x - (1.0 - lam) * old + a * dt**2
    return new, (new - x) / dt


class UserArrayVerlet(msd.Integrator):
    """A user's damped Verlet written like task 5: ``dynamics.acceleration`` and arrays."""

    def __init__(self, damping: float) -> None:
        self.damping = damping

    def step(self, x: np.ndarray, v: np.ndarray, dt: float, dynamics: msd.Dynamics) -> tuple:
        return damped_verlet_update(x, v, dynamics.acceleration(x, v), dt, self.damping)


class UserAdvanceVerlet(UserArrayVerlet):
    """The same update handed to ``dynamics.advance``, which the numba kernel compiles."""

    def step(self, x: np.ndarray, v: np.ndarray, dt: float, dynamics: msd.Dynamics) -> tuple:
        return dynamics.advance(damped_verlet_update, x, v, dt, self.damping)


def engine_stepper(body: msd.Body, implementation: str) -> tuple:
    integrator = {
        "engine-symplectic": msd.SymplecticEuler(),
        "user-arrays": UserArrayVerlet(0.01),
        "user-advance": UserAdvanceVerlet(0.01),
    }.get(implementation, msd.Verlet(0.01))
    kernel = "numpy" if implementation == "engine-numpy" else "numba"
    forces = [msd.Gravity(GRAVITY), msd.Ground(height=0.0)]
    sim = msd.Simulation(body, integrator, dt=DT, forces=forces, kernel=kernel)
    return sim.step, body.n_springs


def numpy_edge_list_stepper(body: msd.Body) -> tuple:
    """Position Verlet with damping λ over the spring list in plain numpy."""
    a, b = body.spring_a, body.spring_b
    k, rest, m = body.stiffness, body.rest_lengths, body.masses
    g, lam = np.array(GRAVITY), 0.01
    state = {"x": body.positions.copy(), "old": body.positions.copy()}

    def step() -> None:
        x = state["x"]
        d = x[a] - x[b]
        length = np.sqrt((d * d).sum(axis=1))
        f = (k * (rest - length) / length)[:, None] * d
        force = np.empty_like(x)
        for axis in range(3):
            force[:, axis] = np.bincount(a, f[:, axis], len(x)) - np.bincount(b, f[:, axis], len(x))
        acceleration = force / m[:, None] + g
        x_new = (2 - lam) * x - (1 - lam) * state["old"] + acceleration * DT * DT
        np.maximum(x_new[:, 1], 0.0, out=x_new[:, 1])  # the ground
        state["old"], state["x"] = x, x_new

    return step, body.n_springs


def spring_loop_stepper(body: msd.Body) -> tuple:
    """Forces of a sample of springs by `Spring.force`, then a numpy Verlet update."""
    springs = body.springs[: min(LOOP_SAMPLE, body.n_springs)]
    m, g = body.masses, np.array(GRAVITY)

    def step() -> None:
        force = np.zeros_like(body.positions)
        for spring in springs:
            f = spring.force()
            force[spring.a] += f
            force[spring.b] -= f
        x = body.positions
        x_new = 2 * x - (x - body.velocities * DT) + (force / m[:, None] + g) * DT * DT
        body.velocities[:] = (x_new - x) / DT
        x[:] = x_new

    return step, len(springs)


def measure(implementation: str, n: int, repeats: int, warmup: int) -> dict:
    """Run one implementation on one grid (in this process) and return its row."""
    body, build = make_grid(n)
    if implementation.startswith(("engine", "user")):
        step, timed_springs = engine_stepper(body, implementation)
    elif implementation == "numpy-edge-list":
        step, timed_springs = numpy_edge_list_stepper(body)
    else:
        step, timed_springs = spring_loop_stepper(body)
        repeats, warmup = min(repeats, 3), 1
    for _ in range(warmup):
        step()
    times = []
    for _ in range(repeats):
        start = time.perf_counter()
        step()
        times.append(time.perf_counter() - start)
    tracemalloc.start()
    before = tracemalloc.get_traced_memory()[0]
    step()
    step_bytes = tracemalloc.get_traced_memory()[1] - before
    tracemalloc.stop()
    seconds = float(np.median(times)) * body.n_springs / timed_springs
    return {
        "implementation": implementation,
        "n": n,
        "particles": len(body),
        "springs": body.n_springs,
        "ms": 1e3 * seconds,
        "extrapolated": timed_springs < body.n_springs,
        "mups": body.n_springs / seconds / 1e6,
        "step_mib": step_bytes / 2**20,
        "rss_mib": resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024,
        "build_s": build,
    }


def compile_seconds() -> float:
    """Time for the first steps of a small 2-D and a 3-D body (compiling or loading kernels)."""
    start = time.perf_counter()
    for body in (msd.Body.grid((6, 5), neighbours=(1, 2)), make_grid(17)[0]):  # 17³: threaded
        sim = msd.Simulation(body, msd.Verlet(0.01), forces=[msd.Gravity(GRAVITY[: body.dim])])
        body.spring_damping[:] = 0.1
        sim.run(steps=1)
    return time.perf_counter() - start


def small_body_seconds(kernel: str, resting: bool, steps: int = 10_000) -> float:
    """Seconds for ``steps`` steps of a 2-D gallery body: 20×15 particles, (1, 2) springs
    with dashpots, 3 fixed, gravity, ground, drag; in the air or resting on the ground."""
    body = msd.Body.grid(
        (20, 15), spacing=0.1, stiffness=50.0, neighbours=(1, 2), origin=(0, 0.5 if resting else 50)
    )
    body.fixed[:3] = True
    body.spring_damping[:] = 0.05
    forces = [msd.Gravity((0, -9.81)), msd.Ground(), msd.Drag(0.1)]
    sim = msd.Simulation(body, msd.Verlet(0.01), dt=1e-3, forces=forces, kernel=kernel)
    sim.run(steps=500)  # warm up, and land when resting
    start = time.perf_counter()
    for _ in range(steps):
        sim.step()
    return time.perf_counter() - start


def implicit_ms(n: int = 20, repeats: int = 5) -> float:
    """Median ms per `ImplicitEuler` step on an n³ grid with (1, 2, 3) (dt = 10 ms)."""
    body = make_grid(n)[0]
    forces = [msd.Gravity(GRAVITY), msd.Ground()]
    sim = msd.Simulation(body, msd.ImplicitEuler(), dt=1e-2, forces=forces)
    sim.step()
    times = []
    for _ in range(repeats):
        start = time.perf_counter()
        sim.step()
        times.append(time.perf_counter() - start)
    return 1e3 * float(np.median(times))


def child(arguments: list[str], env: dict | None = None) -> dict:
    """Run this script in a fresh process and return the JSON it prints."""
    command = [sys.executable, os.path.abspath(__file__), "--child", *arguments]
    output = subprocess.run(command, check=True, capture_output=True, text=True, env=env)
    return json.loads(output.stdout.splitlines()[-1])


def machine() -> str:
    cpu = platform.processor() or platform.machine()
    try:
        with open("/proc/cpuinfo") as info:
            cpu = next(line.split(":", 1)[1].strip() for line in info if "model name" in line)
    except (OSError, StopIteration):
        pass
    import numba
    import scipy

    return (
        f"CPU {cpu}, {os.cpu_count()} cores, numba threads {numba.get_num_threads()}; "
        f"Python {platform.python_version()}, numpy {np.__version__}, scipy {scipy.__version__}, "
        f"numba {numba.__version__}, msdlab {msd.__version__}, {platform.system()}; "
        f"load average {os.getloadavg()[0]:.2f} (other programs running slow the timings)"
    )


def table(rows: list[dict]) -> str:
    columns = ["implementation", "n", "particles", "springs", "ms/step", "M upd/s"]
    columns += ["step MiB", "peak RSS MiB", "build s"]
    lines = ["| " + " | ".join(columns) + " |", "|" + " --- |" * len(columns)]
    for r in rows:
        approx = "~" if r["extrapolated"] else ""
        lines.append(
            f"| {IMPLEMENTATIONS[r['implementation']]} | {r['n']} | {r['particles']:,} | "
            f"{r['springs']:,} | {approx}{r['ms']:.3g} | {approx}{r['mups']:.3g} | "
            f"{r['step_mib']:.1f} | {r['rss_mib']:.0f} | {r['build_s']:.2f} |"
        )
    return "\n".join(lines)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--n", type=int, nargs="+", default=[20, 40, 60, 100], help="grid sizes")
    parser.add_argument("--skip-100", action="store_true", help="leave out n = 100")
    parser.add_argument("--repeats", type=int, default=9, help="timed steps per row")
    parser.add_argument("--warmup", type=int, default=2, help="steps before timing")
    parser.add_argument(
        "--only", nargs="+", choices=list(IMPLEMENTATIONS), default=list(IMPLEMENTATIONS)
    )
    parser.add_argument("--child", action="store_true", help=argparse.SUPPRESS)
    parser.add_argument("--implementation", help=argparse.SUPPRESS)
    parser.add_argument("--compile", action="store_true", help=argparse.SUPPRESS)
    parser.add_argument("--small", action="store_true", help=argparse.SUPPRESS)
    args = parser.parse_args()
    if args.child:
        if args.compile:
            print(json.dumps({"seconds": compile_seconds()}))
        elif args.small:
            rows = {
                f"{kernel}, {where}": small_body_seconds(kernel, where == "resting on the ground")
                for kernel in ("numba", "numpy")
                for where in ("in the air", "resting on the ground")
            }
            rows["implicit"] = implicit_ms()
            print(json.dumps(rows))
        else:
            print(json.dumps(measure(args.implementation, args.n[0], args.repeats, args.warmup)))
        return

    print(machine())
    with tempfile.TemporaryDirectory() as cache:
        env = dict(os.environ, NUMBA_CACHE_DIR=cache)
        cold = child(["--compile"], env)["seconds"]
        warm = child(["--compile"], env)["seconds"]
    print(
        f"numba kernels: {cold:.2f} s to compile (empty cache), {warm:.2f} s to load from "
        "the cache (first steps of a small 2-D and a 17³ body, including their set-up)"
    )
    sizes = [n for n in args.n if not (args.skip_100 and n == 100)]
    rows = []
    for n in sizes:
        for implementation in args.only:
            arguments = ["--implementation", implementation, "--n", str(n)]
            arguments += ["--repeats", str(args.repeats), "--warmup", str(args.warmup)]
            rows.append(child(arguments))
            print(f"  measured {implementation} n={n}", file=sys.stderr)
    print(table(rows))
    print(f"load average at the end: {os.getloadavg()[0]:.2f}")
    print("~: Spring.force loop timed on a sample of springs and scaled to all of them.")
    small = child(["--small"])
    print(f"ImplicitEuler, 20³ grid with (1, 2, 3): {small.pop('implicit'):.0f} ms per step")
    print("10 000 steps of a 2-D body (300 particles, 1 097 springs with dashpots, 3 fixed,")
    print("gravity, ground, drag, Verlet λ = 0.01), seconds:")
    for name, seconds in small.items():
        print(f"  {name}: {seconds:.2f} s ({100 * seconds:.0f} µs per step)")


if __name__ == "__main__":
    main()
