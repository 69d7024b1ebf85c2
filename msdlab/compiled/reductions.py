"""Sums over the state at the end of a step, compiled: one pass each, no temporary arrays.

The same quantities as the numpy kernel's (`kernels.finite`, `equations.damping_work`).
The work is summed over blocks of `BLOCK` particles, then over the blocks in order, so
one thread and several give the same sum; it may differ from numpy's in the last bits.
"""

from __future__ import annotations

import numba
import numpy as np

BLOCK = 4096  # particles per partial sum
PARALLEL_MIN_PARTICLES = 20_000  # from here a pass over the state runs on the threads


@numba.njit(cache=True, parallel=True, fastmath={"reassoc"})
def finite(x, v):
    """Whether every coordinate of positions ``x`` and velocities ``v`` (N, d) is finite:
    0·u is 0 for a finite u and NaN for an infinite or NaN one, and a sum of them is 0
    in any order, so the loop may add them on vector registers, and for a big state
    (`PARALLEL_MIN_PARTICLES`) on the threads. One loop reads both arrays: two streams at
    once read memory faster than one after the other."""
    xs, vs = x.ravel(), v.ravel()
    if len(xs) != len(vs):  # the loop reads both up to len(xs), unchecked
        raise ValueError("positions and velocities must have the same shape")
    zero = 0.0
    if len(x) < PARALLEL_MIN_PARTICLES:
        for i in range(len(xs)):
            zero += 0.0 * xs[i] + 0.0 * vs[i]
    else:
        for i in numba.prange(len(xs)):
            zero += 0.0 * xs[i] + 0.0 * vs[i]
    return zero == 0.0


@numba.njit(cache=True)
def _kick_dots(masses, v_before, v_after, block):
    """Σ m v_before·(v_before + v_after) (kg·m²/s²) over the particles of ``block``."""
    total = 0.0
    for i in range(block * BLOCK, min(len(masses), (block + 1) * BLOCK)):
        dot = 0.0
        for q in range(v_before.shape[1]):
            dot += v_before[i, q] * (v_before[i, q] + v_after[i, q])
        total += masses[i] * dot
    return total


@numba.njit(cache=True, parallel=True)
def damping_work(masses, v_before, v_after, factor):
    """`equations.damping_work`: (1 - factor)·½ Σ m v_before·(v_before + v_after) (J).

    Summed by blocks of `BLOCK` particles, on the threads for a big state
    (`PARALLEL_MIN_PARTICLES`), then over the blocks in order: the same sum either way.
    """
    sums = np.empty((len(masses) + BLOCK - 1) // BLOCK)
    if len(masses) < PARALLEL_MIN_PARTICLES:
        for block in range(len(sums)):
            sums[block] = _kick_dots(masses, v_before, v_after, block)
    else:
        for block in numba.prange(len(sums)):
            sums[block] = _kick_dots(masses, v_before, v_after, block)
    total = 0.0
    for block in range(len(sums)):
        total += sums[block]
    return (1.0 - factor) * (0.5 * total)
