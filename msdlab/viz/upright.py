"""Which axis points up in a picture: taken from the scene's gravity or floor.

A scene with gravity along -y (the brief's cube) is drawn with y up, one with
gravity along -z with z up; without gravity the floor's normal decides, and
without either 2-D bodies have y up and 3-D ones z up. A recorded run has no
forces, but its ledger does: the gravitational energy changes as -M g·Δx_cm, so
`up_of_run` fits g to the recorded centre of mass and potential energy.
"""

from __future__ import annotations

from collections.abc import Iterable

import numpy as np

from .. import Gravity, Simulation, Trajectory
from ..interaction import Ground

UPS = ("x", "y", "z")


def default_up(dim: int) -> str:
    """The vertical axis when nothing says otherwise: y in 2-D, z in 3-D."""
    return "y" if dim == 2 else "z"


def axis_of(vector: Iterable[float]) -> str:
    """The name of the axis along which ``vector`` is largest."""
    return UPS[int(np.argmax(np.abs(np.asarray(vector, dtype=float))))]


def up_of(sim: Simulation) -> str:
    """The vertical axis of ``sim``: against its gravity, else its ground's normal."""
    for force in sim.forces:
        if isinstance(force, Gravity) and np.any(force.g):
            return axis_of(force.g)
    for constraint in sim.constraints:
        if isinstance(constraint, Ground):
            return axis_of(constraint.normal_of(sim.body))
    return default_up(sim.body.dim)


def up_of_run(run: Trajectory) -> str:
    """The vertical axis of a recorded run, from how its potential energy follows its
    centre of mass (U = -M g·x_cm + const); the default when the fit says nothing."""
    dim = run.body.dim
    potential = np.asarray(run.energies.potential, dtype=float)
    if dim == 2 or len(potential) != len(run) or len(run) < 3:
        return default_up(dim)
    masses = run.body.masses
    centre = np.einsum("n,fnd->fd", masses, run.positions) / masses.sum()
    spread = np.ptp(centre, axis=0)
    moving = spread > 1e-6 * spread.max()  # rounding noise on a still axis fits anything
    if np.ptp(potential) <= 0 or not moving.any():
        return default_up(dim)
    moves = centre[:, moving] - centre[:, moving].mean(axis=0)
    slope = np.zeros(dim)
    slope[moving] = np.linalg.lstsq(moves, potential - potential.mean(), rcond=None)[0]
    return axis_of(slope)


def resolve_up(up: str | None, source: Simulation | Trajectory | None, dim: int) -> str:
    """``up`` if given, else the vertical axis of ``source`` (a simulation or a run)."""
    if up is not None:
        return up
    if isinstance(source, Simulation):
        return up_of(source)
    if isinstance(source, Trajectory):
        return up_of_run(source)
    return default_up(dim)
