"""How much memory does a big grid body take? Peak RSS of an n³ grid over a few steps.

One fresh process per integrator builds ``Body.grid((n, n, n), neighbours=(1, 2, 3))``
(13 springs per particle, as the speed benchmark's peer), lifts it above the ground
and takes three steps with gravity, ground and the energy ledger. It prints the
resident set size after building the body, after reading its stiffness
(``body.spring_set.stiffness``, held through the steps: one value per offset of the
lattice) and the process's peak after the steps,
in MiB (``resource.getrusage``; numpy, numba and the compiled kernels included).

    python benchmarks/grid_memory.py            # n = 100
    python benchmarks/grid_memory.py --n 60 100
"""

from __future__ import annotations

import argparse
import json
import subprocess
import sys

STEPS = 3


def measure(n: int, integrator: str) -> dict:
    """RSS (MiB) after `Body.grid` and the peak after `STEPS` steps, in this process."""
    import resource

    import msdlab as msd
    from msdlab.engine.backends.process import configure_process

    configure_process()

    def rss_mib() -> float:
        with open("/proc/self/status") as status:
            line = next(line for line in status if line.startswith("VmRSS:"))
        return int(line.split()[1]) / 1024

    body = msd.Body.grid((n, n, n), spacing=1.0, stiffness=100.0, neighbours=(1, 2, 3))
    body.positions[:, 1] += 1.05  # in the air, like the peer's grid
    built = rss_mib()
    stiffness = body.spring_set.stiffness  # held: what reading the springs' values costs
    read = rss_mib()
    chosen = {"symplectic": msd.SymplecticEuler(), "verlet": msd.Verlet(0.01)}[integrator]
    forces = [msd.Gravity((0.0, -9.81, 0.0)), msd.Ground()]
    sim = msd.Simulation(body, chosen, dt=1e-3, forces=forces)
    for _ in range(STEPS):
        sim.step()
    peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024
    values = int(stiffness.size)  # one per offset: 13
    return {"springs": body.n_springs, "values": values, "built": built, "read": read, "peak": peak}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--n", type=int, nargs="+", default=[100])
    parser.add_argument("--child", nargs=2, help=argparse.SUPPRESS)
    args = parser.parse_args()
    if args.child:
        print(json.dumps(measure(int(args.child[0]), args.child[1])))
        return
    print(
        "| n | springs | integrator | RSS after Body.grid MiB | after reading the stiffness "
        "MiB | peak RSS, 3 steps MiB |"
    )
    print("| --- | --- | --- | --- | --- | --- |")
    for n in args.n:
        for integrator in ("symplectic", "verlet"):
            command = [sys.executable, __file__, "--child", str(n), integrator]
            row = json.loads(subprocess.run(command, check=True, capture_output=True).stdout)
            built, read, peak = (f"{row[key]:.0f}" for key in ("built", "read", "peak"))
            print(f"| {n} | {row['springs']:,} | {integrator} | {built} | {read} | {peak} |")


if __name__ == "__main__":
    main()
