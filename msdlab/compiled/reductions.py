"""Sums over the state at the end of a step, compiled: one pass each, no temporary arrays.

The same quantities as the numpy kernel's (`kernels.finite`, `equations.damping_work`),
summed particle by particle, so they may differ from numpy's sums in the last bits.
"""

from __future__ import annotations

import numba


@numba.njit(cache=True, fastmath={"reassoc"})
def finite(x, v):
    """Whether every coordinate of positions ``x`` and velocities ``v`` (N, d) is finite:
    0·u is 0 for a finite u and NaN for an infinite or NaN one, and a sum of them is 0
    in any order, so the loop may add them on vector registers."""
    zero = 0.0
    for values in (x.ravel(), v.ravel()):
        for i in range(len(values)):
            zero += 0.0 * values[i]
    return zero == 0.0


@numba.njit(cache=True)
def damping_work(masses, v_before, v_after, factor):
    """`equations.damping_work`: (1 - factor)·½ Σ m v_before·(v_before + v_after) (J)."""
    total = 0.0
    for i in range(len(masses)):
        dot = 0.0
        for q in range(v_before.shape[1]):
            dot += v_before[i, q] * (v_before[i, q] + v_after[i, q])
        total += masses[i] * dot
    return (1.0 - factor) * (0.5 * total)
