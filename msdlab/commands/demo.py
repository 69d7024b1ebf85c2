"""``msdlab demo``: drop a jelly cube on the floor, print its energy ledger, save a plot."""

from __future__ import annotations

import argparse
from pathlib import Path

import numpy as np

from ..body import Body, rotation_matrix
from ..constraints import Ground
from ..forces import Gravity
from ..integrators import Verlet
from ..simulation import Simulation
from ..stability import max_stable_dt


def register(subparsers: argparse._SubParsersAction) -> None:
    parser = subparsers.add_parser(
        "demo",
        help="drop a jelly cube on the floor and show its energy ledger",
        description=__doc__,
    )
    parser.add_argument("--out", type=Path, default=Path("msdlab-output"), help="output folder")
    parser.add_argument("--size", type=int, default=8, help="particles per cube edge")
    parser.set_defaults(run=run)


def run(args: argparse.Namespace) -> int:
    """The brief's solved setting: k = 0.5, λ = 0.01, g = -0.001, dt = 0.4, 58.3° about z."""
    n = args.size
    body = Body.grid(
        (n, n, n), spacing=2 / n, stiffness=0.5, neighbours=(1, 2, 3), origin=(-1, 1.5, -1)
    )
    body.rotate(rotation_matrix(58.3, axis=(0, 0, 1)))
    integrator = Verlet(damping=0.01)
    sim = Simulation(body, integrator, dt=0.4, forces=[Gravity((0, -0.001, 0)), Ground(0.0)])
    limit = max_stable_dt(body, integrator)
    print(f"{body}: Verlet λ = 0.01, dt = 0.4 (predicted stable limit {limit:.3g})")
    trajectory = sim.run(steps=1500, record_every=10)
    print(trajectory.energies.table(rows=10))
    args.out.mkdir(parents=True, exist_ok=True)
    path = args.out / "demo_energy.png"
    _plot_energy(trajectory.energies.as_arrays(), path)
    print(f"energy plot written to {path.resolve()}")
    return 0


def _plot_energy(columns: dict[str, np.ndarray], path: Path) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(7, 4))
    for name in ("kinetic", "elastic", "potential", "total", "drift"):
        ax.plot(columns["time"], columns[name], label=name)
    ax.set_xlabel("time (steps × dt)")
    ax.set_ylabel("energy")
    ax.legend()
    fig.tight_layout()
    fig.savefig(path, dpi=100)
    plt.close(fig)
