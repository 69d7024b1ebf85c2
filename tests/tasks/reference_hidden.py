"""Instructor-only references for the hidden checks (left out of the student release).

These are answers to tasks, written independently of the solution files: the
hidden checks compare a submission with them. The public checks never import
this module; they take their expected values from the engine and from physics.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

import msdlab as msd
from msdlab.course import oracles
from msdlab.course.reference_cache import cached


def first_floor_contact(y0: float, dt: float, g: float, limit: int = 1_000_000) -> int:
    """Steps of the template until a particle at rest at height y0 first reaches y <= 0."""
    y_old = y = float(y0)
    for step in range(1, limit + 1):
        v = (y - y_old) / dt + dt * g
        y_old, y = y, y + dt * v
        if y <= 0.0:
            return step
    raise ValueError(f"no floor contact within {limit} steps (y0 = {y0}, dt = {dt}, g = {g})")


def pair_acceleration(
    positions: np.ndarray, pairs: np.ndarray, rest_lengths: np.ndarray | float, stiffness: float
) -> np.ndarray:
    """Eq. (1.1)-(1.2) over index pairs (E, 2) of positions (N, 3), unit masses."""
    positions = np.asarray(positions, dtype=float)
    pairs = np.asarray(pairs, dtype=np.int64).reshape(-1, 2)
    d = positions[pairs[:, 0]] - positions[pairs[:, 1]]
    length = np.linalg.norm(d, axis=1, keepdims=True)
    direction = np.divide(d, length, out=np.zeros_like(d), where=length > 0)
    rest = np.broadcast_to(np.asarray(rest_lengths, dtype=float), (len(pairs),))[:, None]
    f = stiffness * (rest - length) * direction
    a = np.zeros_like(positions)
    np.add.at(a, pairs[:, 0], f)
    np.subtract.at(a, pairs[:, 1], f)
    return a


def axis_pairs(shape: Sequence[int]) -> np.ndarray:
    """Index pairs (E, 2) of axis neighbours (i, i + 1 along each axis) of a C-order grid."""
    index = np.arange(int(np.prod(shape))).reshape(shape)
    pairs = []
    for axis, n in enumerate(shape):
        if n > 1:
            first = np.take(index, np.arange(n - 1), axis=axis).ravel()
            second = np.take(index, np.arange(1, n), axis=axis).ravel()
            pairs.append(np.stack([first, second], axis=1))
    return np.concatenate(pairs) if pairs else np.zeros((0, 2), dtype=np.int64)


@cached  # the same for every submission: computed once per grading run
def drop_rotated_cube(
    angle_degrees: float,
    axis: Sequence[float],
    neighbours: Sequence[int],
    n: int = 4,
    steps: int = 1500,
    stiffness: float = 0.5,
    lift: float = 0.05,
) -> float:
    """Flatness after / before of an n³ cube (spacing 2/n) rotated, put on the floor and run.

    Template setting: msd.Verlet(), dt = 0.1, gravity (0, -0.001, 0), floor y = 0;
    the rotated cube is shifted up so its lowest particle is at y = ``lift``.
    """
    body = oracles.grid_body((n, n, n), 2.0 / n, stiffness, neighbours)
    body.rotate(msd.rotation_matrix(angle_degrees, axis))
    body.positions[:, 1] += lift - body.positions[:, 1].min()
    before = oracles.flatness(body.positions)
    forces = [msd.Gravity(oracles.TEMPLATE_GRAVITY), msd.Ground(0.0)]
    msd.Simulation(body, msd.Verlet(), oracles.TEMPLATE_DT, forces).run(
        steps=steps, record_every=steps
    )
    return oracles.flatness(body.positions) / before


def solved_setting(integrator: msd.Integrator) -> np.ndarray:
    """Positions every 50 of 800 steps of the solved setting run by ``integrator``: a 4³
    jelly (spacing and k 0.5, 26 neighbours) turned 58.3° about z, dt = 0.4, gravity, floor."""
    body = msd.Body.grid((4, 4, 4), 0.5, 0.5, neighbours=(1, 2, 3), origin=(-1.0, 1.5, -1.0))
    body.rotate(msd.rotation_matrix(58.3, (0.0, 0.0, 1.0)))
    forces = [msd.Gravity(oracles.TEMPLATE_GRAVITY), msd.Ground(0.0)]
    return msd.Simulation(body, integrator, 0.4, forces).run(steps=800, record_every=50).positions


@cached  # the same for every submission: computed once per grading run
def solved_setting_verlet(damping: float = 0.01) -> np.ndarray:
    """`solved_setting` run by the engine's msd.Verlet(damping)."""
    return solved_setting(msd.Verlet(damping))
