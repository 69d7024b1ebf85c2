"""Hanging cloth (seed ``001``, "Mass Spring Model" notebook).

The notebook's model: a 10×10 mesh of nodes over x ∈ [0, 10], y ∈ [0, 8] at
height z = 10, F = m g + Σ k (len - len_rest) along each edge with
g = (0, 0, -9.8), dx/dt = v, dv/dt = (F - λ v)/m from rest, stepped by Euler's
method. The notebook never ran (undefined names, in-place updates); this is
a working version with the top edge (y = 8) pinned at its corners or along
the whole row.

Its loop ``v += h f; x += h v`` updates x with the *new* v: that is the
symplectic (semi-implicit) Euler, the default here, stable for
dt < 2/ω_max. Textbook forward Euler (`ExplicitEuler`, both updates from the
old state) is stable only where the damping beats the stiffness,
ω² dt < λ/m for every mode: at these settings its stiffest mode needs
dt < 10⁻⁴ s, so at dt = 0.01 s it blows up within a few dozen steps, which
`Simulation` reports as `SimulationDiverged` with that diagnosis.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from .. import Body, Gravity, Integrator, Simulation, SymplecticEuler, ViscousDamping
from ..engine.model.lattice import lattice_springs

PINS = ("corners", "row")


def cloth(
    *,
    nodes: Sequence[int] = (10, 10),
    extent: Sequence[float] = (10.0, 8.0),
    height: float = 10.0,
    pin: str = "corners",
    mass: float = 0.1,
    stiffness: float = 100.0,
    shear: bool = True,
    damping: float = 0.1,
    gravity: float = -9.8,
    dt: float = 0.01,
    integrator: Integrator | None = None,
) -> Simulation:
    """A ``nodes`` mesh over [0, extent_x]×[0, extent_y] at z = ``height`` (m), top edge pinned.

    ``pin``: "corners" (the two ends of the edge y = extent_y) or "row" (all of it).
    ``mass`` kg per node, ``stiffness`` N/m per edge, ``damping`` λ in N·s/m
    (the force -λ v on every node). ``shear`` adds both diagonals of every cell
    (Provot's shear springs) so the cloth does not fold like a mechanism; the
    notebook's mesh has the edges only (``shear=False``).
    """
    if pin not in PINS:
        raise ValueError(f"unknown pin {pin!r}; choose one of {', '.join(PINS)}")
    nx, ny = (int(n) for n in nodes)
    if nx < 2 or ny < 2:
        raise ValueError(f"the cloth needs at least 2×2 nodes, got {nx}×{ny}")
    ij = np.stack(np.meshgrid(np.arange(nx), np.arange(ny), indexing="ij"), axis=-1)
    ij = ij.reshape(-1, 2)
    spacing = np.asarray(extent, dtype=float) / (nx - 1, ny - 1)
    springs = lattice_springs((nx, ny), (1, 2) if shear else (1,), spacing, stiffness, 0.0)
    top = ij[:, 1] == ny - 1
    fixed = top if pin == "row" else top & ((ij[:, 0] == 0) | (ij[:, 0] == nx - 1))
    body = Body.from_arrays(
        np.column_stack([ij * spacing, np.full(len(ij), float(height))]),
        springs,
        masses=mass,
        fixed=fixed,
    )
    forces = [Gravity((0.0, 0.0, gravity)), ViscousDamping(damping)]
    return Simulation(body, integrator or SymplecticEuler(), dt, forces)
