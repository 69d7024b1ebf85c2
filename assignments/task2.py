"""Task 2: springs between axis neighbours, with rest length one grid spacing.

Every particle of the grid is joined by a spring to its 6 axis neighbours
(i±1, j, k), (i, j±1, k), (i, j, k±1), where they exist: particles on a face,
edge or corner of the grid have 5, 4 or 3. With unit masses eq. (1.1) and
(1.2) of the brief give the acceleration of particle i::

    a_i = Σ_j f_ij,   f_ij = k (l_ij - |x_i - x_j|) (x_i - x_j) / |x_i - x_j|

"Rest length 1" means one grid spacing: l_ij = h (in world units, h = 2/N in
the template). Write `spring_acceleration`; the given `msd_kernel` adds it to
the template's step, so `run` drops a grid of springs on the floor.
``msdlab check 2`` grades it.
"""

from __future__ import annotations

import numpy as np

N = 20
SPACING = 2.0 / N
ORIGIN = (-1.0, 1.5, -1.0)
STIFFNESS = 0.5  # k of every spring
DT = 0.1
GRAVITY = (0.0, -0.001, 0.0)
FLOOR = 0.0


# --------------------------------------------------------------------------- your answer
def spring_acceleration(x: np.ndarray, spacing: float, stiffness: float) -> np.ndarray:
    """Acceleration (nx, ny, nz, 3) of every grid particle from its axis springs, eq. (1.1)-(1.2).

    ``x`` (nx, ny, nz, 3) are the positions, x[i, j, k] the particle (i, j, k);
    each spring joins axis neighbours, has rest length ``spacing`` and stiffness
    ``stiffness``; the masses are 1. A spring whose two ends are at the same
    point has no direction: it adds nothing (no NaN). ``x`` is not modified.
    """
    x = np.asarray(x, dtype=float)
    if x.ndim != 4 or x.shape[-1] != 3:
        raise ValueError(f"x must hold grid positions of shape (nx, ny, nz, 3), got {x.shape}")
    raise NotImplementedError(
        "Task 2: sum eq. (1.2) over the (up to 6) axis neighbours of every particle, rest length = "
        "spacing; border particles have fewer neighbours."
    )


# --------------------------------------------------------------------------- given code
def initial_grid(shape: tuple[int, int, int] = (N, N, N), spacing: float = SPACING) -> np.ndarray:
    """Positions (nx, ny, nz, 3) of a grid at rest: ORIGIN + spacing·(i, j, k)."""
    if len(shape) != 3 or min(shape) < 1:
        raise ValueError(f"shape must be three sizes >= 1, got {shape!r}")
    index = np.stack(np.meshgrid(*(np.arange(n) for n in shape), indexing="ij"), axis=-1)
    return np.asarray(ORIGIN) + spacing * index


def msd_kernel(
    old: np.ndarray,
    current: np.ndarray,
    new: np.ndarray,
    spacing: float = SPACING,
    stiffness: float = STIFFNESS,
    dt: float = DT,
) -> None:
    """The template's step with springs: Verlet with a = gravity + springs, then the floor."""
    if not (old.shape == current.shape == new.shape):
        raise ValueError(f"old, current and new differ in shape: {old.shape}, {current.shape}")
    if not dt > 0:
        raise ValueError(f"the time step dt must be > 0, got {dt!r}")
    a = np.asarray(GRAVITY) + spring_acceleration(current, spacing, stiffness)
    v = (current - old) / dt + dt * a
    new[...] = current + dt * v
    np.maximum(new[..., 1], FLOOR, out=new[..., 1])


def run(
    steps: int,
    shape: tuple[int, int, int] = (N, N, N),
    spacing: float = SPACING,
    stiffness: float = STIFFNESS,
    dt: float = DT,
) -> np.ndarray:
    """Positions (nx, ny, nz, 3) after ``steps`` steps of the template with springs, from rest."""
    current = initial_grid(shape, spacing)
    old, new = current.copy(), np.empty_like(current)
    for _ in range(steps):
        msd_kernel(old, current, new, spacing, stiffness, dt)
        old, current, new = current, new, old
    return current
