"""Task 3: tilt or rotate the initial layout. What changes?

Rotate the grid before it falls (`rotation_matrix`, `rotate_layout`), write the
spring acceleration for a body given as a list of springs, so that it does not
care how the body is oriented (`spring_acceleration`), and measure what
happens to a rotated cube held by axis springs only (`drop_rotated_cube`).

Physics to find: a lattice of axis springs has no shear stiffness. Upright,
gravity pulls along the vertical springs and the cube stands; tilted, nothing
resists shearing and it folds flat. The forces themselves are the same physics
in any orientation: rotating the body rotates every force with it.
``msdlab check 3`` grades the functions.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

import msdlab as msd

N = 4  # particles per edge of the cube dropped by `drop_rotated_cube`
STIFFNESS = 0.5
DT = 0.1
GRAVITY = (0.0, -0.001, 0.0)
LIFT = 0.05  # height of the lowest particle above the floor y = 0 at the start


# --------------------------------------------------------------------------- given code
def flatness(positions: np.ndarray) -> float:
    """How thin a cloud of points is: √(smallest eigenvalue of its gyration tensor).

    The same for any rotation or translation of the points; a cube keeps it,
    a cube folded flat has it close to 0.
    """
    points = np.asarray(positions, dtype=float).reshape(-1, 3)
    centred = points - points.mean(axis=0)
    gyration = centred.T @ centred / len(points)
    return float(np.sqrt(max(np.linalg.eigvalsh(gyration)[0], 0.0)))


def _checked_axis(
    axis: Sequence[float], takes: str = "rotation_matrix takes (angle_degrees, axis)"
) -> np.ndarray:
    """``axis`` as a float array, else ValueError; where the axis is a single number (the
    angle, given where the axis goes) the message names the order, ``takes``."""
    axis = np.asarray(axis, dtype=float)
    if axis.shape != (3,) or not np.all(np.isfinite(axis)) or not np.any(axis):
        order = f": the angle? {takes}, as msd.rotation_matrix does" if axis.shape == () else ""
        raise ValueError(
            f"the rotation axis must be a non-zero 3-vector, got {axis.tolist()}{order}"
        )
    return axis


# --------------------------------------------------------------------------- your answers
def rotation_matrix(angle_degrees: float, axis: Sequence[float]) -> np.ndarray:
    """The (3, 3) matrix of a right-handed rotation by ``angle_degrees`` about ``axis``.

    ``axis`` is any non-zero 3-vector (its length does not matter); the arguments come in
    the order of the engine's ``msd.rotation_matrix(angle_degrees, axis)``. Rodrigues:
    R = cos θ I + sin θ [n]× + (1 - cos θ) n nᵀ with n the unit axis.
    """
    axis = _checked_axis(axis)
    ### BEGIN SOLUTION
    # TODO: build the rotation matrix by Rodrigues' formula (normalise the axis first).
    n = axis / np.linalg.norm(axis)
    theta = np.radians(angle_degrees)
    cross = np.array([[0.0, -n[2], n[1]], [n[2], 0.0, -n[0]], [-n[1], n[0], 0.0]])
    return np.cos(theta) * np.eye(3) + np.sin(theta) * cross + (1 - np.cos(theta)) * np.outer(n, n)
    ### END SOLUTION


def rotate_layout(positions: np.ndarray, angle_degrees: float, axis: Sequence[float]) -> np.ndarray:
    """Positions (..., 3) rotated by ``angle_degrees`` about ``axis`` through their centroid.

    Returns a new array of the same shape, e.g. (nx, ny, nz, 3) for a grid; the
    centroid (mean position) stays where it was.
    """
    positions = np.asarray(positions, dtype=float)
    if positions.shape[-1] != 3:
        raise ValueError(f"positions must have shape (..., 3), got {positions.shape}")
    axis = _checked_axis(axis, "rotate_layout takes (positions, angle_degrees, axis)")
    ### BEGIN SOLUTION
    # TODO: rotate every position about the centroid with rotation_matrix(angle_degrees, axis).
    rotation = rotation_matrix(angle_degrees, axis)
    points = positions.reshape(-1, 3)
    centroid = points.mean(axis=0)
    return ((points - centroid) @ rotation.T + centroid).reshape(positions.shape)
    ### END SOLUTION


def spring_acceleration(
    positions: np.ndarray, springs: np.ndarray, rest_lengths: np.ndarray, stiffness: float
) -> np.ndarray:
    """Acceleration (N, 3) of unit-mass particles from a list of springs, eq. (1.1)-(1.2).

    ``positions`` (N, 3); ``springs`` (E, 2) integer particle indices (i, j),
    each spring listed once; ``rest_lengths`` (E,) l_ij. Particle i gets
    f_ij = k (l_ij - |x_i - x_j|)(x_i - x_j)/|x_i - x_j| and j gets -f_ij.
    Nothing here depends on the orientation of the body. A spring whose ends
    are at the same point adds nothing (no NaN). The inputs are not modified.
    """
    positions = np.asarray(positions, dtype=float)
    springs = np.asarray(springs).reshape(-1, 2)
    rest_lengths = np.asarray(rest_lengths, dtype=float).reshape(-1)
    if len(springs) != len(rest_lengths):
        raise ValueError(f"{len(springs)} springs but {len(rest_lengths)} rest lengths")
    ### BEGIN SOLUTION
    # TODO: compute f_ij of eq. (1.2) for every spring and add it to particle i and -f_ij to j.
    i, j = springs[:, 0], springs[:, 1]
    d = positions[i] - positions[j]
    length = np.linalg.norm(d, axis=1, keepdims=True)
    direction = np.divide(d, length, out=np.zeros_like(d), where=length > 0)
    f = stiffness * (rest_lengths[:, None] - length) * direction
    a = np.zeros_like(positions)
    for axis in range(3):
        a[:, axis] = np.bincount(i, f[:, axis], len(positions)) - np.bincount(
            j, f[:, axis], len(positions)
        )
    return a
    ### END SOLUTION


def drop_rotated_cube(
    angle_degrees: float,
    axis: Sequence[float],
    neighbours: Sequence[int] = (1,),
    steps: int = 1500,
) -> float:
    """Measure how flat a rotated cube gets: flatness after / before the run (1 = kept its shape).

    The experiment: an N × N × N grid (``msd.Body.grid``, spacing 2/N,
    stiffness STIFFNESS, unit masses, springs to ``neighbours``: 1 = axis
    springs) rotated with `rotate_layout`, shifted up so that its lowest
    particle is at y = LIFT, then ``steps`` steps of the template's scheme
    (``msd.Verlet()``, dt = DT) with gravity and the floor
    (``msd.Gravity(GRAVITY)``, ``msd.Ground(0.0)``).
    """
    axis = _checked_axis(axis, "drop_rotated_cube takes (angle_degrees, axis, neighbours, steps)")
    ### BEGIN SOLUTION
    # TODO: build, rotate and lift the cube, run the simulation, return the flatness ratio.
    body = msd.Body.grid((N, N, N), spacing=2.0 / N, stiffness=STIFFNESS, neighbours=neighbours)
    body.positions = rotate_layout(body.positions, angle_degrees, axis)
    body.positions[:, 1] += LIFT - body.positions[:, 1].min()
    before = flatness(body.positions)
    simulation = msd.Simulation(body, msd.Verlet(), DT, [msd.Gravity(GRAVITY), msd.Ground(0.0)])
    simulation.run(steps=steps, record_every=steps)
    return flatness(body.positions) / before
    ### END SOLUTION
