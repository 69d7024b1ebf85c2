"""Task 4: neighbours at √2 and √3 spacings. Does the cube keep its shape? What does it cost?

Besides its 6 axis neighbours (distance h), a grid particle has 12 face-diagonal
neighbours (h√2) and 8 body-diagonal ones (h√3): 26 in all. Springs to them
give the lattice the shear stiffness it lacked in task 3. Build the springs of
a grid (`neighbour_offsets`, `grid_springs`), show that a rotated cube now
holds its shape (`drop_rotated_cube`), and measure how the cost of a step
grows with the number of springs (`step_cost`). ``msdlab check 4`` grades them.

Neighbours are named by their squared distance in grid units, as in the
brief: 1 (axis, rest length h), 2 (face diagonal, h√2), 3 (body diagonal, h√3).
"""

from __future__ import annotations

import time
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
    """How thin a cloud of points is: √(smallest eigenvalue of its gyration tensor)."""
    points = np.asarray(positions, dtype=float).reshape(-1, 3)
    centred = points - points.mean(axis=0)
    gyration = centred.T @ centred / len(points)
    return float(np.sqrt(max(np.linalg.eigvalsh(gyration)[0], 0.0)))


def grid_positions(shape: Sequence[int], spacing: float) -> np.ndarray:
    """Positions (nx·ny·nz, 3) of a grid, C order: row ravel_multi_index((i, j, k), shape)
    is spacing·(i, j, k)."""
    index = np.stack(np.meshgrid(*(np.arange(n) for n in shape), indexing="ij"), axis=-1)
    return spacing * index.reshape(-1, 3).astype(float)


def _checked_squared_distances(squared_distances: Sequence[int]) -> list[int]:
    values = sorted(set(squared_distances))
    if not values or any(s not in (1, 2, 3) for s in values):
        raise ValueError(
            f"squared_distances must be some of 1 (axis), 2 (face diagonal), 3 (body "
            f"diagonal); got {list(squared_distances)!r}"
        )
    return values


def _checked_axis(axis: Sequence[float]) -> np.ndarray:
    """``axis`` as a float array, else ValueError; where the axis is a single number (the
    angle, given where the axis goes) the message names the order of the arguments."""
    axis = np.asarray(axis, dtype=float)
    if axis.shape != (3,) or not np.all(np.isfinite(axis)) or not np.any(axis):
        order = (
            ": the angle? drop_rotated_cube takes (angle_degrees, axis, squared_distances, "
            "steps), as msd.rotation_matrix does"
            if axis.shape == ()
            else ""
        )
        raise ValueError(
            f"the rotation axis must be a non-zero 3-vector, got {axis.tolist()}{order}"
        )
    return axis


# --------------------------------------------------------------------------- your answers
def neighbour_offsets(squared_distances: Sequence[int] = (1, 2, 3)) -> np.ndarray:
    """All grid offsets (M, 3) of integers in {-1, 0, 1} whose squared length is in the list.

    Both o and -o are included: (1,) gives the 6 axis neighbours, (1, 2, 3)
    all 26 neighbours of an interior particle.
    """
    wanted = _checked_squared_distances(squared_distances)
    raise NotImplementedError(
        "Task 4: list the offsets (di, dj, dk) in {-1, 0, 1}³ with di² + dj² + dk² in wanted."
    )


def grid_springs(
    shape: Sequence[int], spacing: float, squared_distances: Sequence[int] = (1, 2, 3)
) -> tuple[np.ndarray, np.ndarray]:
    """The springs of a grid: index pairs (E, 2) and rest lengths (E,), each spring once.

    Particle (i, j, k) is row ``np.ravel_multi_index((i, j, k), shape)`` of
    `grid_positions` (C order). Springs join particles whose offset has a
    squared length in ``squared_distances``; the rest length is the distance
    at rest, spacing·√(squared length), so the grid at rest is free of stress.
    """
    shape = tuple(int(n) for n in shape)
    if len(shape) != 3 or min(shape) < 1:
        raise ValueError(f"shape must be three sizes >= 1, got {shape!r}")
    raise NotImplementedError(
        "Task 4: for every offset of neighbour_offsets (one of o and -o), join each particle to the"
        " particle at its grid coordinates + offset, where that exists."
    )


def drop_rotated_cube(
    angle_degrees: float,
    axis: Sequence[float],
    squared_distances: Sequence[int] = (1, 2, 3),
    steps: int = 1500,
) -> float:
    """Flatness after / before a run of a rotated N³ cube held by the springs of `grid_springs`.

    The experiment of task 3 with your springs: grid_positions((N, N, N), 2/N)
    rotated by ``msd.rotation_matrix(angle_degrees, axis)`` about the centroid,
    shifted up so that its lowest particle is at y = LIFT, springs of stiffness
    STIFFNESS, unit masses (``msd.Body.from_arrays``), then ``steps`` steps of
    ``msd.Verlet()`` at dt = DT with ``msd.Gravity(GRAVITY)`` and ``msd.Ground(0.0)``.
    """
    axis = _checked_axis(axis)
    raise NotImplementedError(
        "Task 4: build the rotated cube with your springs, run it as in task 3, return the ratio."
    )


def step_cost(
    n: int, squared_distances: Sequence[int] = (1, 2, 3), steps: int = 20
) -> tuple[int, float]:
    """(number of springs, seconds per step) of an n³ grid with these neighbours.

    Build the body from `grid_springs` (spacing 2/n, stiffness STIFFNESS),
    time ``steps`` steps of ``msd.Simulation(body, msd.Verlet(), DT,
    [msd.Gravity(GRAVITY)])`` with ``time.perf_counter`` and divide by ``steps``.
    Compare n = 10 with (1,) and with (1, 2, 3): how do cost and springs grow?
    """
    raise NotImplementedError(
        "Task 4: build the body, time `steps` simulation steps, return (springs, seconds per step)."
    )
