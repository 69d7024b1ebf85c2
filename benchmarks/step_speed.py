"""How fast does msdlab step a big body, next to a hand-written numba edge loop?

The yardstick is ``../shared/bench``'s peer, ``NumbaParallel(Problem(n))``: a
parallel numba loop over the springs with per-thread force buffers, on an n³
grid with 13 springs per particle (rest 1, √2, √3), k = 100 N/m, m = 1 kg,
gravity, a ground clamp at y = 0, symplectic Euler, dt = 1 ms, float64.
msdlab runs the same body (same positions) as a full `Simulation.step`:
forces, integrator, fixed particles, ground, energy ledger, divergence check,
with `SymplecticEuler` and with `Verlet(0.01)`, on two layouts of the springs:

- grid: `Body.grid(..., neighbours=(1, 2, 3))`, which the numba kernel gathers
  per particle by grid offset;
- shuffled: the same springs in a random order, added with `add_springs` to a
  body that is not a grid, which the kernel sums with its edge loop.

The machine is shared and noisy, so the peer runs in the same process,
interleaved with msdlab: batch of the peer, batch of each msdlab integrator,
repeated; a ratio is msdlab's batch over the peer's batch next to it. The
table shows the median ratio and its range over the repeats, and the medians
of the times. Each (n, layout) runs in its own process; its peak RSS is taken
before the peer is built, so it is msdlab's (the body, the kernels, Python).

    python benchmarks/step_speed.py                 # n = 20, 40, 60, 100
    python benchmarks/step_speed.py --n 20 60 --repeats 15
    python benchmarks/step_speed.py --skip-100 --no-extras

It ends with the compile time, the ImplicitEuler step on a 20³ grid and 10 000
steps of a small 2-D body in the air and resting on the ground (``--no-extras``
leaves them out).
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
from pathlib import Path

import numpy as np

import msdlab as msd
from msdlab.engine.backends.process import configure_process

configure_process()  # the process settings of the command line

PEER = Path(__file__).resolve().parents[1].parent / "shared" / "bench"
DT = 1e-3
GRAVITY = (0.0, -9.81, 0.0)
INTEGRATORS = {"symplectic": msd.SymplecticEuler, "verlet": lambda: msd.Verlet(0.01)}


def peer_problem(n: int) -> tuple:
    """The peer stepper and its `Problem` (imported from ../shared/bench)."""
    sys.path.insert(0, str(PEER))
    from common import Problem  # found at run time
    from impl_numba import NumbaParallel

    problem = Problem(n)
    return NumbaParallel(problem), problem


def make_grid(n: int) -> tuple[msd.Body, float]:
    """The peer's grid as a msdlab body (same spacing, k, masses), and seconds to build it."""
    start = time.perf_counter()
    body = msd.Body.grid((n, n, n), spacing=1.0, stiffness=100.0, neighbours=(1, 2, 3))
    return body, time.perf_counter() - start


def shuffled(grid: msd.Body, seed: int = 0) -> msd.Body:
    """The same particles and springs, the springs in a random order, not a grid."""
    order = np.random.default_rng(seed).permutation(grid.n_springs)
    body = msd.Body.from_arrays(grid.positions, masses=grid.masses)
    edges = grid.edges()
    pairs = np.stack([edges.a[order], edges.b[order]], axis=1)
    body.add_springs(pairs, edges.stiffness[order], edges.rest_lengths[order])
    return body


def simulations(n: int, layout: str, x0: np.ndarray) -> tuple[dict, float]:
    """One `Simulation` per integrator on its own copy of the body, and the build seconds."""
    sims = {}
    build = 0.0
    for name, integrator in INTEGRATORS.items():
        body, build = make_grid(n)
        if layout == "shuffled":
            body = shuffled(body)
        body.positions[:] = x0
        forces = [msd.Gravity(GRAVITY), msd.Ground(height=0.0)]
        sims[name] = msd.Simulation(body, integrator(), dt=DT, forces=forces)
    return sims, build


def compare(n: int, layout: str, repeats: int) -> dict:
    """Interleaved batches of the peer and of msdlab; the ratios and times of one (n, layout)."""
    sys.path.insert(0, str(PEER))
    from common import Problem  # found at run time

    sims, build = simulations(n, layout, Problem(n).x0)
    for sim in sims.values():
        sim.run(steps=2)  # compile or load the kernels
    rss = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024
    peer, _ = peer_problem(n)
    peer.step(2)
    start = time.perf_counter()
    peer.step(2)
    steps = max(1, round(0.15 / ((time.perf_counter() - start) / 2)))  # ~0.15 s per batch
    times: dict[str, list[float]] = {"peer": [], **{name: [] for name in sims}}
    ratios: dict[str, list[float]] = {name: [] for name in sims}
    for _ in range(repeats):
        for name, sim in sims.items():
            start = time.perf_counter()
            peer.step(steps)
            peer_seconds = (time.perf_counter() - start) / steps
            start = time.perf_counter()
            for _ in range(steps):
                sim.step()
            seconds = (time.perf_counter() - start) / steps
            times["peer"].append(peer_seconds)
            times[name].append(seconds)
            ratios[name].append(seconds / peer_seconds)
    return {
        "n": n,
        "layout": layout,
        "springs": next(iter(sims.values())).body.n_springs,
        "ms": {name: 1e3 * float(np.median(t)) for name, t in times.items()},
        "ratio": {name: [float(np.median(r)), min(r), max(r)] for name, r in ratios.items()},
        "rss_mib": rss,
        "build_s": build,
        "batch": steps,
    }


def compile_seconds() -> float:
    """Time for the first steps of a small 2-D and a 3-D body (compiling or loading kernels)."""
    start = time.perf_counter()
    for body in (msd.Body.grid((6, 5), neighbours=(1, 2)), make_grid(17)[0]):  # 17³: threaded
        sim = msd.Simulation(body, msd.Verlet(0.01), forces=[msd.Gravity(GRAVITY[: body.dim])])
        body.set_springs(damping=0.1)
        sim.run(steps=1)
    return time.perf_counter() - start


def small_body_seconds(kernel: str, resting: bool, steps: int = 10_000) -> float:
    """Seconds for ``steps`` steps of a 2-D gallery body: 20×15 particles, (1, 2) springs
    with dashpots, 3 fixed, gravity, ground, drag; in the air or resting on the ground."""
    body = msd.Body.grid(
        (20, 15), spacing=0.1, stiffness=50.0, neighbours=(1, 2), origin=(0, 0.5 if resting else 50)
    )
    body.fixed[:3] = True
    body.set_springs(damping=0.05)
    forces = [msd.Gravity((0, -9.81)), msd.Ground(), msd.Drag(0.1)]
    sim = msd.Simulation(body, msd.Verlet(0.01), dt=1e-3, forces=forces, kernel=kernel)
    sim.run(steps=500)  # warm up, and land when resting
    start = time.perf_counter()
    for _ in range(steps):
        sim.step()
    return time.perf_counter() - start


def resting_ledger_ratios(n: int = 20, repeats: int = 9, steps: int = 50) -> dict[str, list[float]]:
    """Step time with the energy ledger over without it, median and range, for an n³ grid
    with dashpots resting on the ground (gravity, ground), interleaved in batches."""
    ratios = {}
    for name, integrator in INTEGRATORS.items():
        sims = []
        for ledger in (True, False):
            body = msd.Body.grid((n,) * 3, spacing=0.1, stiffness=200.0, neighbours=(1, 2, 3))
            body.set_springs(damping=0.05)
            forces = [msd.Gravity(GRAVITY), msd.Ground()]
            sim = msd.Simulation(body, integrator(), dt=DT, forces=forces, ledger=ledger)
            sim.run(steps=300)  # settle onto the ground
            sims.append(sim)
        batches = []
        for _ in range(repeats):
            seconds = []
            for sim in sims:
                start = time.perf_counter()
                for _ in range(steps):
                    sim.step()
                seconds.append(time.perf_counter() - start)
            batches.append(seconds[0] / seconds[1])
        ratios[name] = [float(np.median(batches)), min(batches), max(batches)]
    return ratios


def implicit_ms(n: int = 20, repeats: int = 5) -> float:
    """Median ms per `ImplicitEuler` step on an n³ grid with (1, 2, 3) (dt = 10 ms)."""
    body = make_grid(n)[0]
    body.positions[:, 1] += 1.05  # in the air, like the peer's grid
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
    columns = ["n", "springs", "springs laid out", "peer ms"]
    columns += ["SymplecticEuler ms", "÷ peer (range)", "Verlet(0.01) ms", "÷ peer (range)"]
    columns += ["peak RSS MiB", "build s"]
    lines = ["| " + " | ".join(columns) + " |", "|" + " --- |" * len(columns)]
    for r in rows:
        cells = [str(r["n"]), f"{r['springs']:,}", r["layout"], f"{r['ms']['peer']:.3g}"]
        for name in INTEGRATORS:
            median, low, high = r["ratio"][name]
            cells += [f"{r['ms'][name]:.3g}", f"{median:.2f} ({low:.2f}–{high:.2f})"]
        cells += [f"{r['rss_mib']:.0f}", f"{r['build_s']:.2f}"]
        lines.append("| " + " | ".join(cells) + " |")
    return "\n".join(lines)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--n", type=int, nargs="+", default=[20, 40, 60, 100], help="grid sizes")
    parser.add_argument("--skip-100", action="store_true", help="leave out n = 100")
    parser.add_argument("--repeats", type=int, default=7, help="interleaved batches per row")
    parser.add_argument("--layouts", nargs="+", choices=["grid", "shuffled"])
    parser.add_argument("--no-extras", action="store_true", help="only the table")
    parser.add_argument("--child", action="store_true", help=argparse.SUPPRESS)
    parser.add_argument("--compile", action="store_true", help=argparse.SUPPRESS)
    parser.add_argument("--small", action="store_true", help=argparse.SUPPRESS)
    args = parser.parse_args()
    layouts = args.layouts or ["grid", "shuffled"]
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
            rows["ledger"] = resting_ledger_ratios()
            print(json.dumps(rows))
        else:
            print(json.dumps(compare(args.n[0], layouts[0], args.repeats)))
        return

    if not (PEER / "common.py").exists():
        sys.exit(f"the peer is not at {PEER}; this benchmark needs ../shared/bench beside the repo")
    print(machine())
    rows = []
    for n in [n for n in args.n if not (args.skip_100 and n == 100)]:
        for layout in layouts:
            rows.append(child(["--n", str(n), "--layouts", layout, "--repeats", str(args.repeats)]))
            print(f"  measured n={n} {layout}", file=sys.stderr)
    print(table(rows))
    print(f"load average at the end: {os.getloadavg()[0]:.2f}")
    if args.no_extras:
        return
    with tempfile.TemporaryDirectory() as cache:
        env = dict(os.environ, NUMBA_CACHE_DIR=cache)
        cold = child(["--compile"], env)["seconds"]
        warm = child(["--compile"], env)["seconds"]
    print(
        f"numba kernels: {cold:.2f} s to compile (empty cache), {warm:.2f} s to load from "
        "the cache (first steps of a small 2-D and a 17³ body, including their set-up)"
    )
    small = child(["--small"])
    print(f"ImplicitEuler, 20³ grid with (1, 2, 3): {small.pop('implicit'):.0f} ms per step")
    print("20³ grid with dashpots resting on the ground, a step with the ledger ÷ without:")
    for name, (median, low, high) in small.pop("ledger").items():
        print(f"  {name}: {median:.2f} ({low:.2f}–{high:.2f})")
    print("10 000 steps of a 2-D body (300 particles, 1 097 springs with dashpots, 3 fixed,")
    print("gravity, ground, drag, Verlet λ = 0.01), seconds:")
    for name, seconds in small.items():
        print(f"  {name}: {seconds:.2f} s ({100 * seconds:.0f} µs per step)")


if __name__ == "__main__":
    main()
