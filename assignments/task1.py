"""Task 1: the template's falling grid, and what its ``msd_kernel`` really does.

The template is a crude particle system: a cube of N × N × N particles, lifted
above the floor y = 0, falls under a constant acceleration. Read the given code
(`initial_grid`, `msd_kernel`, `run_template`), run it, and answer the questions
below as short functions. ``msdlab check 1`` grades the answers.

Units are the template's: lengths in the units of the [-1, 1) cube, time in
the template's seconds (dt = 0.1), unit masses.
"""

from __future__ import annotations

import math

import numpy as np

N = 20  # particles per edge (the original also ran N = 30)
EDGE = 2.0  # edge length of the grid's cube: x and z in [-1, 1)
SPACING = EDGE / N  # grid spacing h
ORIGIN = (-1.0, 1.5, -1.0)  # position of particle (0, 0, 0)
DT = 0.1  # time step
GRAVITY = (0.0, -0.001, 0.0)  # the template's acceleration a
FLOOR = 0.0  # the floor is the plane y = FLOOR

SCHEMES = (
    "explicit euler",
    "symplectic euler",
    "position verlet",
    "velocity verlet",
    "runge-kutta 4",
)


# --------------------------------------------------------------------------- given code
def initial_grid(n: int = N) -> np.ndarray:
    """Positions (n, n, n, 3) of the template's grid: ``ORIGIN + (EDGE / n)·(i, j, k)``.

    Particle (i, j, k) sits at ORIGIN + (EDGE/n)·(i, j, k): x and z in [-1, 1),
    y in [1.5, 1.5 + EDGE).
    """
    if isinstance(n, bool) or not isinstance(n, (int, np.integer)) or n < 1:
        raise ValueError(f"n is the number of particles per edge, an integer >= 1; got {n!r}")
    coord = np.stack(np.meshgrid(*3 * [np.arange(n)], indexing="ij"), axis=-1)
    return np.asarray(ORIGIN, dtype=float) + (EDGE / n) * coord


def msd_kernel(
    old: np.ndarray,
    current: np.ndarray,
    new: np.ndarray,
    dt: float = DT,
    acceleration: tuple[float, float, float] = GRAVITY,
) -> None:
    """One template step of every particle, written into ``new`` (arrays (..., 3)).

    The original ran one GPU thread per particle; each did::

        v = (current - old) / dt      # velocity from the last two positions
        v += dt * a                   # accelerate
        new = current + dt * v        # move
        if new.y < 0: new.y = 0       # the floor: clamp, no bounce, no friction
    """
    if not (old.shape == current.shape == new.shape) or current.shape[-1] != 3:
        raise ValueError(
            "old, current and new must be position arrays of one shape (..., 3); got "
            f"{old.shape}, {current.shape}, {new.shape}"
        )
    if not dt > 0:
        raise ValueError(f"the time step dt must be > 0, got {dt!r}")
    v = (current - old) / dt
    v = v + dt * np.asarray(acceleration, dtype=float)
    new[...] = current + dt * v
    np.maximum(new[..., 1], FLOOR, out=new[..., 1])


def run_template(
    steps: int,
    n: int = N,
    dt: float = DT,
    acceleration: tuple[float, float, float] = GRAVITY,
) -> np.ndarray:
    """Positions (n, n, n, 3) after ``steps`` template steps from rest.

    Three buffers as in the original: old = current at the start (zero initial
    velocity); after each step they rotate: old <- current <- new.
    """
    if isinstance(steps, bool) or not isinstance(steps, (int, np.integer)) or steps < 0:
        raise ValueError(f"steps must be an integer >= 0, got {steps!r}")
    current = initial_grid(n)
    old = current.copy()
    new = np.empty_like(current)
    for _ in range(steps):
        msd_kernel(old, current, new, dt, acceleration)
        old, current, new = current, new, old
    return current


# --------------------------------------------------------------------------- your answers
def particle_count(n: int = N) -> int:
    """How many particles the template simulates with ``n`` particles per edge."""
    raise NotImplementedError(
        "Task 1: return the number of particles of the template's grid with n per edge."
    )


def integration_scheme() -> str:
    """Which integration scheme ``msd_kernel`` really is: one of `SCHEMES`.

    Hint: put the first two lines of the kernel into the third and compare the
    result with eq. (1.3) of the brief.
    """
    raise NotImplementedError(
        "Task 1: return the name (one of SCHEMES) of the scheme msd_kernel implements."
    )


def verlet_step(
    old: np.ndarray,
    current: np.ndarray,
    dt: float,
    acceleration: tuple[float, float, float],
) -> np.ndarray:
    """The kernel's new positions (floor left out) in the form of eq. (1.3).

    x(t + dt) = 2·x(t) - x(t - dt) + a·dt², with ``current`` = x(t) and
    ``old`` = x(t - dt), arrays (..., 3). Returns x(t + dt) as a new array.
    """
    raise NotImplementedError(
        "Task 1: return x(t + dt) by eq. (1.3) from old = x(t - dt) and current = x(t)."
    )


def height_after(steps: int, y0: float = ORIGIN[1], dt: float = DT, g: float = GRAVITY[1]) -> float:
    """Height of a particle after ``steps`` template steps from rest at height ``y0``.

    The floor is left out (the particle may go below y = 0); ``g`` is the y
    component of the acceleration. Hint: the template moves the particle by
    g·dt² in the first step, 2·g·dt² in the second, ...
    """
    raise NotImplementedError(
        "Task 1: return the height after `steps` template steps (closed form or a loop)."
    )


def steps_to_floor(y0: float = ORIGIN[1], dt: float = DT, g: float = GRAVITY[1]) -> int:
    """After how many template steps a particle at rest at height ``y0`` first reaches the floor.

    That is the first step n whose new height (before the clamp) is <= 0: the
    step in which the floor clamp first acts on it. For the bottom layer of
    your template (y0 = ORIGIN[1] = 1.5) the exact free fall y0 + ½ g t²
    would land at t = 54.8: the template's steps fall a little faster.
    Needs y0 > 0, g < 0 and dt > 0: raise ValueError otherwise (a particle that
    starts on or below the floor, or does not fall, has no first contact to count).
    """
    raise NotImplementedError(
        "Task 1: return the first step after which the particle is at or below the floor y = 0."
    )
