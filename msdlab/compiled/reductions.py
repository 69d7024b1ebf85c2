"""The finiteness check of the state at the end of a step, compiled: one pass, no temporary
arrays (`kernels.finite`)."""

from __future__ import annotations

import numba

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
